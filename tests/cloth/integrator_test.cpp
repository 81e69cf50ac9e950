// Analytic checks of the explicit prediction (paper eq. 2 in the anchor's frame, symplectic
// Euler; method §3.3, §3.4) and of the springs in compliance form (constraints.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "drape/systems/cloth/constraints.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/integrator.hpp"
#include "drape/systems/cloth_systems.hpp"

namespace drape {
namespace {

// Symplectic Euler under constant g: v_n = -g n h, y_n = y0 - g h^2 n (n + 1) / 2, so the
// error against the exact y0 - g t^2 / 2 is exactly g h t / 2 (first order in h).
TEST(FreeFall, MatchesTheSchemeAndTheAnalyticSolutionWithinItsKnownError) {
    Matrix3X x = Matrix3X::Zero(3, 1), v = Matrix3X::Zero(3, 1);
    const VectorX inv_mass = VectorX::Constant(1, 50), drag = VectorX::Zero(1);
    const Real h = Real(1.0 / 120.0);
    const Vec3 g(0, -standard_gravity_m_s2, 0);
    for (int n = 1; n <= 120; ++n) {
        predict_particles(x, v, inv_mass, drag, 0, 1, AnchorMotion{}, InertiaScales{}, g, h);
        const double t = n * double(h);
        const double scheme = -double(standard_gravity_m_s2) * double(h) * double(h) * n * (n + 1) / 2;
        const double exact = -double(standard_gravity_m_s2) * t * t / 2;
        ASSERT_NEAR(x(1, 0), scheme, 1e-5 * (1 + std::abs(scheme)));
        ASSERT_NEAR(scheme - exact, -double(standard_gravity_m_s2) * double(h) * t / 2, 1e-9);
        ASSERT_NEAR(v(1, 0), -double(standard_gravity_m_s2) * t, 1e-4);
    }
}

// The whole pipeline (integration, constraint and collision rounds, layer-2 placement, no
// colliders) on a free, unstretched sheet: every particle falls like a single one.
TEST(FreeFall, WholeSheetFallsRigidlyThroughTheThreeSystems) {
    for (ClothModel model : {ClothModel::simplified, ClothModel::classic}) {
        Registry registry;
        RectangleParams params;
        params.pin_top_row = false;
        params.hanging = false;
        params.material.drag_N_s_m3 = 0;
        params.model = model;
        const Entity e = *attach_rectangle(registry, params);
        Scheduler scheduler;
        add_cloth_systems(scheduler);
        const Matrix3X x0 = registry.get<Garment>(e).state.x;
        const int frames = 30;
        for (int i = 0; i < frames; ++i) ASSERT_TRUE(scheduler.tick(registry, 1.0 / 60.0));
        const Garment& g = registry.get<Garment>(e);
        const int n = frames * g.counters.substeps;
        const double h = 1.0 / 60.0 / g.counters.substeps;
        const double drop = double(standard_gravity_m_s2) * h * h * n * (n + 1) / 2;
        for (Eigen::Index p = 0; p < g.state.x.cols(); ++p) {
            ASSERT_NEAR(g.state.x(0, p), x0(0, p), 1e-5);
            ASSERT_NEAR(g.state.x(1, p), x0(1, p) - drop, 1e-4) << "particle " << p;
            ASSERT_NEAR(g.state.x(2, p), x0(2, p), 1e-5);
        }
    }
}

// Eq. 2's drag on a particle in still air (no body motion): v_(n+1) = v_n (1 - h k / m).
TEST(Drag, SlowsAParticleAsTheSchemeSays) {
    Matrix3X x = Matrix3X::Zero(3, 1), v(3, 1);
    v.col(0) = Vec3(2, 0, -1);
    const Real m = Real(0.01), k = Real(0.002), h = Real(1.0 / 240.0);
    const VectorX inv_mass = VectorX::Constant(1, 1 / m), drag = VectorX::Constant(1, k);
    const Vec3 v0 = v.col(0);
    for (int n = 1; n <= 240; ++n) {
        predict_particles(x, v, inv_mass, drag, 0, 1, AnchorMotion{}, InertiaScales{}, Vec3::Zero(), h);
        const double factor = std::pow(1 - double(h * k / m), n);
        ASSERT_NEAR((Vec3(v.col(0)) - v0 * Real(factor)).norm(), 0, 1e-4) << "step " << n;
    }
    EXPECT_LT(drag_step_limit_s(inv_mass, drag, 1), m / k * Real(1.0001));
}

// The drag acts on the particle's velocity against the air, not on the body's acceleration
// (eq. 2's v_b + a_b h/2 term depends on the step and on how hard the body accelerates):
// two steps that differ only in the anchor's acceleration give the same particle, whatever
// the inertia scales.
TEST(Drag, DoesNotDependOnTheBodysAcceleration) {
    for (const InertiaScales inertia : {InertiaScales{1, 1}, InertiaScales{Real(0.5), Real(0.5)}, InertiaScales{0, 0}}) {
        Vec3 result[2];
        for (int i = 0; i < 2; ++i) {
            Matrix3X x(3, 1), v(3, 1);
            x.col(0) = Vec3(Real(0.1), Real(-0.4), Real(0.2));
            v.col(0) = Vec3(Real(0.5), Real(-0.2), Real(0.1));
            const VectorX inv_mass = VectorX::Constant(1, 100), drag = VectorX::Constant(1, Real(0.002));
            AnchorMotion m;
            m.velocity_m_s = m.velocity_before_m_s = Vec3(1, 0, 0);
            m.c1 = m.velocity_m_s * Real(1.0 / 240.0);
            m.acceleration_m_s2 = i == 0 ? Vec3::Zero() : Vec3(40, -30, 20);
            predict_particles(x, v, inv_mass, drag, 0, 1, m, inertia, Vec3(0, -standard_gravity_m_s2, 0), Real(1.0 / 240.0));
            result[i] = v.col(0);
        }
        EXPECT_LT((result[0] - result[1]).norm(), 1e-7) << "inertia " << inertia.linear;
    }
}

// A frame that accelerates and turns, and its substeps: centre and rotation at each step.
struct MovingFrame {
    Vec3 velocity(double t) const { return Vec3(Real(0.8 + 2.0 * t), Real(0.3 * std::sin(4 * t)), Real(-0.5)); }
    Vec3 angular(double t) const { return Vec3(Real(0.2), Real(1.5 + std::sin(3 * t)), Real(-0.4)); }
    // Advances (R, c) over one step of h with the velocities of the step (constant over it).
    void advance(Mat3& r, Vec3& c, double t, double h) const {
        c += velocity(t) * Real(h);
        const Vec3 w = angular(t) * Real(h);
        r = Eigen::AngleAxis<Real>(w.norm(), w.normalized()).toRotationMatrix() * r;
    }
};

// Runs `steps` substeps of predict_particles on one free particle of 10 g (by default no
// gravity, no drag) carried by the moving frame with inertia scales `inertia`; returns its
// world position and velocity, and the frame's last pose.
struct Carried {
    Vec3 x, v;
    Mat3 r;
    Vec3 c;
};
Carried carry(const InertiaScales& inertia, int steps, double h, const Vec3& x0, const Vec3& v0,
              const Vec3& gravity = Vec3::Zero(), Real drag_N_s_m = 0) {
    const MovingFrame frame;
    Matrix3X x(3, 1), v(3, 1);
    x.col(0) = x0;
    v.col(0) = v0;
    const VectorX inv_mass = VectorX::Constant(1, 100), drag = VectorX::Constant(1, drag_N_s_m);
    Mat3 r = Mat3::Identity();
    Vec3 c = Vec3::Zero();
    Vec3 v_before = frame.velocity(0), w_before = frame.angular(0);
    for (int n = 0; n < steps; ++n) {
        const double t = n * h;
        AnchorMotion m;
        m.r0 = r;
        m.c0 = c;
        frame.advance(r, c, t, h);
        m.r1 = r;
        m.c1 = c;
        m.velocity_m_s = frame.velocity(t);
        m.angular_velocity_rad_s = frame.angular(t);
        m.velocity_before_m_s = v_before;
        m.angular_velocity_before_rad_s = w_before;
        m.acceleration_m_s2 = (m.velocity_m_s - v_before) / Real(h);
        predict_particles(x, v, inv_mass, drag, 0, 1, m, inertia, gravity, Real(h));
        v_before = m.velocity_m_s;
        w_before = m.angular_velocity_rad_s;
    }
    return {x.col(0), v.col(0), r, c};
}

// Inertia scales 1 (physical): whatever the anchor does, a free particle keeps its world
// velocity and moves in a straight line. The inertial terms (-m a_b of eq. 2, and the
// frame's rotation) cancel the frame's motion, and the particle is integrated in the world:
// exact up to float rounding at any step.
TEST(AnchorFrame, WithFullInertiaAFreeParticleMovesInAStraightLineWhateverTheBodyDoes) {
    const Vec3 x0(Real(0.3), Real(-0.4), Real(0.2)), v0(Real(0.1), Real(-0.2), Real(0.05));
    for (int refine : {1, 2, 4}) {
        const double h = 1.0 / (120.0 * refine);
        const int steps = 60 * refine;  // 0.5 s
        const Carried p = carry(InertiaScales{}, steps, h, x0, v0);
        const Vec3 expected = x0 + v0 * Real(steps * h);
        const double error = (p.x - expected).norm();
        // Integrated in the world (the frame's motion cancels): exact up to float rounding.
        EXPECT_LT(error, 1e-5) << "h = " << h;
        EXPECT_LT((p.v - v0).norm(), 1e-5) << "h = " << h;
    }
}

// Inertia scales 1 under gravity and air drag: eq. 2 written in the accelerating, turning
// frame must give the world's motion, m dv/dt = m g - k v (still air), whose answer is
//   v(t) = v_inf + (v0 - v_inf) e^(-t k/m),  x(t) = x0 + v_inf t + (v0 - v_inf) (1 - e^(-t k/m)) m/k,
// with v_inf = m g / k. The frame's own velocity (up to 2 m/s) and turn (up to 2.5 rad/s)
// must vanish from the answer: drag on the velocity relative to the frame instead of the
// world, gravity not turned into the frame, or a wrong sign or factor in the inertial terms
// leave an error that does not shrink with the step.
TEST(AnchorFrame, WithFullInertiaGravityAndDragActAsInTheWorld) {
    const Vec3 x0(Real(0.3), Real(-0.4), Real(0.2)), v0(Real(0.6), Real(0.5), Real(-0.3));
    const Vec3 g(0, -standard_gravity_m_s2, 0);
    const double mass = 0.01, k = 0.02, rate = k / mass;  // drag time m/k = 0.5 s
    const double t = 0.5;
    const Eigen::Vector3d v_inf = g.cast<double>() / rate;
    const double decay = std::exp(-rate * t);
    const Eigen::Vector3d v_exact = v_inf + (v0.cast<double>() - v_inf) * decay;
    const Eigen::Vector3d x_exact = x0.cast<double>() + v_inf * t + (v0.cast<double>() - v_inf) * (1 - decay) / rate;
    double previous_x = 0, previous_v = 0;
    for (int refine : {1, 2, 4}) {
        const double h = 1.0 / (120.0 * refine);
        const int steps = 60 * refine;
        const Carried p = carry(InertiaScales{}, steps, h, x0, v0, g, Real(k));
        const double error_x = (p.x.cast<double>() - x_exact).norm();
        const double error_v = (p.v.cast<double>() - v_exact).norm();
        // Symplectic Euler's own error is about |g| h t / 2 = 2 cm at h = 1/120 s.
        EXPECT_LT(error_x, 0.05) << "h = " << h;
        EXPECT_LT(error_v, 0.2) << "h = " << h;
        if (refine > 1) {
            EXPECT_LT(error_x, 0.7 * previous_x) << "first order: the position error shrinks with the step";
            EXPECT_LT(error_v, 0.7 * previous_v) << "first order: the velocity error shrinks with the step";
        }
        previous_x = error_x;
        previous_v = error_v;
    }
}

// Inertia scales 0: a particle at rest in the anchor's frame stays where it is in that frame,
// however the frame accelerates and turns (the garment is carried rigidly).
TEST(AnchorFrame, WithoutInertiaAParticleAtRestInTheFrameStaysThere) {
    const MovingFrame frame;
    const Vec3 r0(Real(0.2), Real(-0.3), Real(0.1));
    const Vec3 v0 = frame.velocity(0) + frame.angular(0).cross(r0);  // at rest in the frame at t = 0
    const Carried p = carry(InertiaScales{0, 0}, 120, 1.0 / 120.0, r0, v0);
    const Vec3 in_frame = p.r.transpose() * (p.x - p.c);
    EXPECT_LT((in_frame - r0).norm(), 1e-4);
}

// Inertia scales 0 under gravity and air drag: the particle feels none of the frame's motion
// and the air moves with the frame (v_air = V + W x d), so in the frame it falls as in still
// air under a gravity that turns with the frame: r' = u, u' = R(t)^T g - (k/m) u. That is
// integrated apart here, in double at a step 64 times finer than the finest below; the
// scheme must approach it at first order. Gravity left unturned, drag on the world velocity
// or an inertial kick left in give an error that does not shrink with the step.
TEST(AnchorFrame, WithoutInertiaGravityAndDragActInTheFrame) {
    const MovingFrame frame;
    const Vec3 r0(Real(0.2), Real(-0.3), Real(0.1));
    const Vec3 v0 = frame.velocity(0) + frame.angular(0).cross(r0);  // at rest in the frame at t = 0
    const Vec3 g(0, -standard_gravity_m_s2, 0);
    const double mass = 0.01, k = 0.02, rate = k / mass;
    const double t_end = 0.5;
    const int fine = 60 * 4 * 64;
    const double hf = t_end / fine;
    Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
    Eigen::Vector3d x = r0.cast<double>(), u = Eigen::Vector3d::Zero();
    for (int n = 0; n < fine; ++n) {
        u += hf * (r.transpose() * g.cast<double>() - rate * u);
        x += hf * u;
        const Eigen::Vector3d w = frame.angular(n * hf).cast<double>() * hf;
        r = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * r;
    }
    ASSERT_GT((x - r0.cast<double>()).norm(), 0.3);  // it fell a good way in the frame
    double previous = 0;
    for (int refine : {1, 2, 4}) {
        const double h = 1.0 / (120.0 * refine);
        const Carried p = carry(InertiaScales{0, 0}, 60 * refine, h, r0, v0, g, Real(k));
        const Eigen::Vector3d in_frame = (p.r.transpose() * (p.x - p.c)).cast<double>();
        const double error = (in_frame - x).norm();
        EXPECT_LT(error, 0.05) << "h = " << h;
        if (refine > 1) {
            EXPECT_LT(error, 0.7 * previous) << "first order: the error shrinks with the step";
        }
        previous = error;
    }
}

// Inertia scales 0 with gravity and air drag: the particle moves relative to the frame
// exactly as it would relative to a frame that stands still (the air moves with the frame:
// only the anchor's motion is taken away, not the physics). A drag on the world velocity
// would lean the particle against the frame's 1-2 m/s.
TEST(AnchorFrame, WithoutInertiaGravityAndDragActInTheFrameAsOnAStillBody) {
    const MovingFrame frame;
    const Vec3 r0(Real(0.2), Real(-0.3), Real(0.1)), u0(Real(0.3), Real(0.1), Real(-0.2));
    const Vec3 g(0, -standard_gravity_m_s2, 0);
    const Real k = Real(0.005);  // drag time m/k = 2 s with the 10 g particle
    const double h = 1.0 / 120.0;
    const int steps = 120;
    // On a still frame.
    Matrix3X x(3, 1), v(3, 1);
    x.col(0) = r0;
    v.col(0) = u0;
    const VectorX inv_mass = VectorX::Constant(1, 100), drag = VectorX::Constant(1, k);
    for (int n = 0; n < steps; ++n) predict_particles(x, v, inv_mass, drag, 0, 1, AnchorMotion{}, InertiaScales{0, 0}, g, Real(h));
    // On the moving frame, starting with the same motion relative to it (the frame starts
    // with the identity pose, so the frame's axes are the world's at t = 0).
    const Vec3 v0 = frame.velocity(0) + frame.angular(0).cross(r0) + u0;
    Matrix3X xs(3, 1), vs(3, 1);
    xs.col(0) = r0;
    vs.col(0) = u0;
    for (int n = 0; n < steps; ++n) predict_particles(xs, vs, inv_mass, drag, 0, 1, AnchorMotion{}, InertiaScales{0, 0}, Vec3::Zero(), Real(h));
    const Carried q = carry(InertiaScales{0, 0}, steps, h, r0, v0, Vec3::Zero(), k);
    EXPECT_LT((Vec3(q.r.transpose() * (q.x - q.c)) - Vec3(xs.col(0))).norm(), 1e-4) << "turning frame, drag";
    // Gravity and drag on a frame that accelerates without turning (gravity keeps its
    // direction in it): the motion relative to the frame is the still frame's.
    Matrix3X xt(3, 1), vt(3, 1);
    const Vec3 a(3, Real(0.5), Real(-1.5)), v_frame0(Real(0.8), 0, Real(0.2));
    xt.col(0) = r0;
    vt.col(0) = u0 + v_frame0;
    Vec3 c = Vec3::Zero(), v_before = v_frame0;
    for (int n = 0; n < steps; ++n) {
        AnchorMotion m;
        m.c0 = c;
        m.velocity_m_s = v_frame0 + a * Real(n * h);
        m.velocity_before_m_s = v_before;
        m.acceleration_m_s2 = a;
        c += m.velocity_m_s * Real(h);
        m.c1 = c;
        predict_particles(xt, vt, inv_mass, drag, 0, 1, m, InertiaScales{0, 0}, g, Real(h));
        v_before = m.velocity_m_s;
    }
    EXPECT_LT((Vec3(xt.col(0)) - c - Vec3(x.col(0))).norm(), 1e-4) << "accelerating frame, gravity and drag";
    EXPECT_GT((Vec3(x.col(0)) - r0).norm(), 0.1) << "the still frame's particle moved (gravity and drag acted)";
}

// Linear inertia s: when the anchor's velocity changes by dV within a step, the particle's
// world velocity changes by (1 - s) dV (no rotation, no gravity, no drag).
TEST(AnchorFrame, LinearInertiaScaleSetsHowMuchOfTheBodysJerkTheParticleFeels) {
    for (Real s : {Real(0), Real(0.5), Real(1)}) {
        Matrix3X x = Matrix3X::Zero(3, 1), v = Matrix3X::Zero(3, 1);
        const VectorX inv_mass = VectorX::Constant(1, 100), drag = VectorX::Zero(1);
        AnchorMotion m;
        m.velocity_before_m_s = Vec3::Zero();
        m.velocity_m_s = Vec3(2, 0, 0);  // a jerk: the body starts moving at 2 m/s
        const Real h = Real(1.0 / 60.0);
        m.c1 = m.velocity_m_s * h;
        m.acceleration_m_s2 = m.velocity_m_s / h;
        predict_particles(x, v, inv_mass, drag, 0, 1, m, InertiaScales{s, 1}, Vec3::Zero(), h);
        EXPECT_NEAR(v(0, 0), (1 - s) * 2, 1e-5) << "s = " << s;
        EXPECT_NEAR(x(0, 0), (1 - s) * 2 * h, 1e-6) << "s = " << s;
    }
}

// A bound on the felt acceleration (InertiaScales::max_linear_m_s2): a jerk of dV within a
// step h whose felt s |dV| / h is beyond the bound b is felt as b h, the rest carried with
// the frame, so the particle's world velocity changes by dV - b h along dV; below the bound,
// and with none (0), the scale alone acts, (1 - s) dV.
TEST(AnchorFrame, AnAccelerationBoundCarriesTheJerkFeltBeyondIt) {
    const Real h = Real(1.0 / 60.0);
    const Vec3 jerk(0, 8, 0);  // an animated jump: the root from 8 m/s up to rest within one step
    for (const Real s : {Real(1), Real(0.5)})
        for (const Real bound : {Real(0), Real(40), Real(1000)}) {
            Matrix3X x = Matrix3X::Zero(3, 1), v = Matrix3X::Zero(3, 1);
            const VectorX inv_mass = VectorX::Constant(1, 100), drag = VectorX::Zero(1);
            AnchorMotion m;
            m.velocity_before_m_s = Vec3::Zero();
            m.velocity_m_s = jerk;
            m.c1 = m.velocity_m_s * h;
            m.acceleration_m_s2 = jerk / h;  // 480 m/s^2
            predict_particles(x, v, inv_mass, drag, 0, 1, m, InertiaScales{s, 1, bound}, Vec3::Zero(), h);
            const bool binds = bound > 0 && s * jerk.norm() / h > bound;
            const Real expected = binds ? jerk.y() - bound * h : (1 - s) * jerk.y();
            EXPECT_NEAR(v(1, 0), expected, 1e-4) << "s = " << s << ", bound = " << bound;
            EXPECT_NEAR(v(0, 0), 0, 1e-6);
            EXPECT_NEAR(x(1, 0), expected * h, 1e-5) << "s = " << s << ", bound = " << bound;
        }
}

// A fall bound (InertiaScales::max_fall_m_s2): an animated jump's root rising at 8 m/s and
// stopping dead within a step h is a body pulled down at 8 / h = 480 m/s^2. A particle
// rising with it under gravity g feels, along gravity, at most the bound b: its world
// velocity becomes (b - g) h upward (at b = g it stops with the body, as cloth on a body in
// free fall does); below the bound, and with none (0), the scale alone acts, 8 s - g h. A
// stop as sudden sideways and a start as sudden upward are felt whole whatever the bound:
// the particle keeps going, or is left behind.
TEST(AnchorFrame, AFallBoundCarriesTheDownwardJerkBeyondItOnly) {
    const Real h = Real(1.0 / 60.0);
    const Vec3 g(0, -standard_gravity_m_s2, 0);
    const VectorX inv_mass = VectorX::Constant(1, 100), drag = VectorX::Zero(1);
    const auto step = [&](const Vec3& v_before, const Vec3& v_after, const Vec3& v0, const InertiaScales& inertia, Matrix3X& x,
                          Matrix3X& v) {
        x = Matrix3X::Zero(3, 1);
        v.resize(3, 1);
        v.col(0) = v0;
        AnchorMotion m;
        m.velocity_before_m_s = v_before;
        m.velocity_m_s = v_after;
        m.c1 = v_after * h;
        m.acceleration_m_s2 = (v_after - v_before) / h;
        predict_particles(x, v, inv_mass, drag, 0, 1, m, inertia, g, h);
    };
    const Vec3 up(0, 8, 0);
    Matrix3X x, v;
    for (const Real s : {Real(1), Real(0.5)})
        for (const Real bound : {Real(0), standard_gravity_m_s2, Real(20), Real(1000)}) {
            step(up, Vec3::Zero(), up, InertiaScales{s, 1, 0, bound}, x, v);
            const bool binds = bound > 0 && s * up.y() / h > bound;
            const Real expected = binds ? (bound - standard_gravity_m_s2) * h : s * up.y() - standard_gravity_m_s2 * h;
            EXPECT_NEAR(v(1, 0), expected, 1e-4) << "s = " << s << ", bound = " << bound;
            EXPECT_NEAR(v(0, 0), 0, 1e-6);
            EXPECT_NEAR(x(1, 0), expected * h, 1e-5) << "s = " << s << ", bound = " << bound;
        }
    const InertiaScales free_fall{1, 1, 0, standard_gravity_m_s2};
    const Vec3 sideways(8, 0, 0);
    step(sideways, Vec3::Zero(), sideways, free_fall, x, v);
    EXPECT_NEAR(v(0, 0), 8, 1e-4);
    EXPECT_NEAR(v(1, 0), -standard_gravity_m_s2 * h, 1e-4);
    step(Vec3::Zero(), up, Vec3::Zero(), free_fall, x, v);
    EXPECT_NEAR(v(1, 0), -standard_gravity_m_s2 * h, 1e-4);
    EXPECT_NEAR(x(1, 0), -standard_gravity_m_s2 * h * h, 1e-6);
}

// The fall bound judges the root's acceleration over its last two steps (AnchorMotion::step_s
// set, as the solver sets it): a clip keyed at 30 Hz and played at 60 moves its root every
// other step, so a walk's hips that gain 0.3 m/s downward in one step and none in the next
// fall at 9 m/s^2 (under g, felt whole), not 18 (bound, partly carried); a root that gains
// 0.5 m/s downward in each of two steps falls at 30 m/s^2, and the step's change beyond the
// bound is carried.
TEST(AnchorFrame, AFallBoundJudgesTheFallOverTwoSteps) {
    const Real h = Real(1.0 / 60.0), gh = standard_gravity_m_s2 * h;
    const Vec3 g(0, -standard_gravity_m_s2, 0);
    const VectorX inv_mass = VectorX::Constant(1, 100), drag = VectorX::Zero(1);
    const InertiaScales free_fall{1, 1, 0, standard_gravity_m_s2};
    const auto step = [&](Real earlier, Real before, Real after, Real step_s) {
        Matrix3X x = Matrix3X::Zero(3, 1), v(3, 1);
        v.col(0) = Vec3(0, before, 0);
        AnchorMotion m;
        m.velocity_earlier_m_s = Vec3(0, earlier, 0);
        m.velocity_before_m_s = Vec3(0, before, 0);
        m.velocity_m_s = Vec3(0, after, 0);
        m.c1 = m.velocity_m_s * h;
        m.step_s = step_s;
        m.acceleration_m_s2 = (m.velocity_m_s - m.velocity_before_m_s) / h;
        predict_particles(x, v, inv_mass, drag, 0, 1, m, free_fall, g, h);
        return v(1, 0);
    };
    EXPECT_NEAR(step(0, 0, Real(-0.3), h), -gh, 1e-4) << "9 m/s^2 over two steps: felt whole, the particle left behind";
    const Real one_step_carried = Real(0.3) * (1 - standard_gravity_m_s2 / (Real(0.3) / h));
    EXPECT_NEAR(step(0, 0, Real(-0.3), 0), -one_step_carried - gh, 1e-4) << "judged over one step it binds";
    const Real carried = Real(0.5) * (1 - standard_gravity_m_s2 / Real(30));
    EXPECT_NEAR(step(0, Real(-0.5), -1, h), Real(-0.5) - carried - gh, 1e-4) << "30 m/s^2 over two steps: the excess carried";
}

// A frame accelerating steadily (a, no turn) with linear inertia scale s, under gravity, no
// drag: relative to the frame the particle feels g - s a, so over t it moves
//   r(t) - r(0) = u0 t + (g - s a) t^2 / 2,   u0 = v0 - V(0),
// and in the world x(t) = x0 + v0 t + (g + (1 - s) a) t^2 / 2. Symplectic Euler's error is
// first order: (g + s a) h t / 2 for this scheme; allowed is twice that (5 mm at the finer
// step). A scale applied as 1 - s, twice per step, or not at all misses by 2.6 cm or more.
TEST(AnchorFrame, LinearInertiaScaleInAnAcceleratingFrameGivesTheAnalyticDisplacement) {
    const Vec3 a(3, Real(0.5), Real(-1.5)), v_frame0(Real(0.5), 0, Real(0.2));
    const Vec3 g(0, -standard_gravity_m_s2, 0);
    const Vec3 x0(Real(0.1), Real(-0.3), Real(0.05)), v0(Real(0.4), Real(0.3), Real(-0.2));
    for (Real s : {Real(0), Real(0.25), Real(1)})
        for (int refine : {1, 4}) {
            const double h = 1.0 / (120.0 * refine), t = 0.25;
            const int steps = static_cast<int>(std::lround(t / h));
            Matrix3X x(3, 1), v(3, 1);
            x.col(0) = x0;
            v.col(0) = v0;
            const VectorX inv_mass = VectorX::Constant(1, 100), drag = VectorX::Zero(1);
            Vec3 c = Vec3::Zero(), v_before = v_frame0;
            for (int n = 0; n < steps; ++n) {
                AnchorMotion m;
                m.c0 = c;
                m.velocity_m_s = v_frame0 + a * Real(n * h);
                m.velocity_before_m_s = v_before;
                m.acceleration_m_s2 = a;
                c += m.velocity_m_s * Real(h);
                m.c1 = c;
                predict_particles(x, v, inv_mass, drag, 0, 1, m, InertiaScales{s, 1}, g, Real(h));
                v_before = m.velocity_m_s;
            }
            const Eigen::Vector3d gd = g.cast<double>(), ad = a.cast<double>();
            const Eigen::Vector3d in_frame = (x.col(0) - c).cast<double>() - x0.cast<double>();
            const Eigen::Vector3d expected = (v0 - v_frame0).cast<double>() * t + (gd - double(s) * ad) * t * t / 2;
            const double bound = (gd + double(s) * ad).norm() * h * t;
            EXPECT_LT((in_frame - expected).norm(), bound) << "s = " << s << ", h = " << h;
            const Eigen::Vector3d world = x.col(0).cast<double>() - x0.cast<double>();
            const Eigen::Vector3d world_expected = v0.cast<double>() * t + (gd + (1 - double(s)) * ad) * t * t / 2;
            EXPECT_LT((world - world_expected).norm(), bound + ad.norm() * h * t) << "s = " << s << ", h = " << h;
        }
}

// A mass hanging from a pinned end on one spring in compliance form settles where the
// spring carries its weight: stretch m g / k, however stiff the spring and however long the
// step (the compliance form has no stability bound, unlike the explicit spring).
TEST(CompliantSpring, SettlesAtTheStaticStretchForAnyStiffnessAndStep) {
    for (Real k : {Real(5), Real(500), Real(5e6)})
        for (Real h : {Real(1.0 / 240.0), Real(1.0 / 15.0)}) {
            SpringPhase phase;
            phase.add(0, 1, 1);
            SpringSet set;
            set.springs = &phase;
            set.strips.parts = {spring_strips(phase)};
            set.compliance = {1 / k};
            set.lambda = {0};
            const Real m = Real(0.1);
            Matrix3X x(3, 2), v = Matrix3X::Zero(3, 2);
            x.col(0) = Vec3::Zero();
            x.col(1) = Vec3(0, -1, 0);
            VectorX inv_mass(2);
            inv_mass << 0, 1 / m;
            const VectorX drag = VectorX::Constant(2, Real(0.05));  // some air: it settles
            Matrix3XRows rows;
            for (int n = 0; n < static_cast<int>(20 / h); ++n) {
                const Matrix3X start = x;
                predict_particles(x, v, inv_mass, drag, 0, 2, AnchorMotion{}, InertiaScales{},
                                  Vec3(0, -standard_gravity_m_s2, 0), h);
                set.lambda[0] = 0;
                rows = x;
                for (int round = 0; round < 4; ++round) solve_springs(set, 0, rows, inv_mass, h, Real(10));
                x = rows;
                v = (x - start) / h;
                v.col(0).setZero();
            }
            const double stretch = -double(x(1, 1)) - 1;
            const double expected = double(m) * double(standard_gravity_m_s2) / double(k);
            ASSERT_TRUE(x.allFinite()) << "k = " << k << ", h = " << h;
            EXPECT_NEAR(stretch, expected, 0.02 * expected + 1e-6) << "k = " << k << ", h = " << h;
        }
}

// Provot's limit (method §4.1) holds whatever the spring: a soft spring pulled far is cut
// back to 1 + limit times its rest length in one pass, the pinned end unmoved.
TEST(CompliantSpring, ProvotsLimitCutsAnOverStretchedSpringBackToTheLimit) {
    SpringPhase phase;
    phase.add(0, 1, 1);
    SpringSet set;
    set.springs = &phase;
    set.strips.parts = {spring_strips(phase)};
    set.compliance = {Real(1e30)};  // no force: the limit alone
    set.lambda = {0};
    Matrix3XRows x(3, 2);
    x.col(0) = Vec3::Zero();
    x.col(1) = Vec3(0, -3, 0);
    VectorX inv_mass(2);
    inv_mass << 0, 10;
    solve_springs(set, 0, x, inv_mass, Real(1.0 / 60.0), Real(0.1));
    EXPECT_EQ(Vec3(x.col(0)), Vec3::Zero());
    EXPECT_NEAR((x.col(1) - x.col(0)).norm(), 1.1, 1e-5);
}

// Strips (constraints.hpp): runs of springs whose ends are consecutive particles are found,
// a chain is split so that no two springs of a strip share a particle, and every spring is
// in exactly one strip.
TEST(SpringStrips, CoverEverySpringOnceAndNoStripSharesAParticle) {
    SpringPhase phase;
    for (std::uint32_t i = 0; i < 9; ++i) phase.add(i, i + 1, 1);         // a chain
    for (std::uint32_t i = 0; i < 10; ++i) phase.add(20 + i, 40 + i, 1);  // a row between two lines
    for (std::uint32_t i = 0; i < 12; ++i) phase.add(60 + i, 63 + i, 1);  // rows three apart
    phase.add(5, 77, 1);                                                   // a stray one
    const auto strips = spring_strips(phase);
    std::vector<int> seen(phase.size(), 0);
    for (const SpringStrip& st : strips) {
        std::vector<std::uint32_t> particles;
        for (std::uint32_t k = 0; k < st.count; ++k) {
            const std::uint32_t s = st.first + k * st.stride;
            ASSERT_LT(s, phase.size());
            ++seen[s];
            EXPECT_EQ(phase.a[s], st.a + k * st.stride);
            EXPECT_EQ(phase.b[s], st.b + k * st.stride);
            particles.push_back(phase.a[s]);
            particles.push_back(phase.b[s]);
        }
        std::sort(particles.begin(), particles.end());
        EXPECT_EQ(std::adjacent_find(particles.begin(), particles.end()), particles.end()) << "a strip shares a particle";
    }
    for (std::size_t s = 0; s < seen.size(); ++s) EXPECT_EQ(seen[s], 1) << "spring " << s;
}

}  // namespace
}  // namespace drape
