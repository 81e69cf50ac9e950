// Analytic checks of the force model and symplectic Euler (method §3.3, §3.4).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "systems/cloth_systems.hpp"
#include "systems/cloth/garment_builder.hpp"
#include "systems/cloth/integrator.hpp"

namespace drape {
namespace {

// Symplectic Euler under constant g: v_n = -g n h, y_n = y0 - g h^2 n (n + 1) / 2, so the
// error against the exact y0 - g t^2 / 2 is exactly g h t / 2 (first order in h).
TEST(FreeFall, MatchesTheSchemeAndTheAnalyticSolutionWithinItsKnownError) {
    Matrix3X x = Matrix3X::Zero(3, 1), v = Matrix3X::Zero(3, 1), force = Matrix3X::Zero(3, 1);
    VectorX inv_mass = VectorX::Constant(1, 50);
    const Real h = Real(1.0 / 120.0);
    const Vec3 g(0, -standard_gravity_m_s2, 0);
    for (int n = 1; n <= 120; ++n) {
        integrate_particles(x, v, inv_mass, force, 1, 1, 0, BodyMotion{}, g, h);
        const double t = n * double(h);
        const double scheme = -double(standard_gravity_m_s2) * double(h) * double(h) * n * (n + 1) / 2;
        const double exact = -double(standard_gravity_m_s2) * t * t / 2;
        ASSERT_NEAR(x(1, 0), scheme, 1e-5 * (1 + std::abs(scheme)));
        ASSERT_NEAR(scheme - exact, -double(standard_gravity_m_s2) * double(h) * t / 2, 1e-9);
        ASSERT_NEAR(v(1, 0), -double(standard_gravity_m_s2) * t, 1e-4);
    }
}

// The whole pipeline (integration, constraints with layer-2 placement, collision without
// colliders) on a free, unstretched sheet: every particle falls like a single one.
TEST(FreeFall, WholeSheetFallsRigidlyThroughTheThreeSystems) {
    for (ClothModel model : {ClothModel::simplified, ClothModel::classic}) {
        Registry registry;
        RectangleParams params;
        params.pin_top_row = false;
        params.hanging = false;
        params.material.drag_N_s_m = 0;
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

// One mass on a spring from a fixed point, no gravity: symplectic Euler turns
// x'' = -w^2 x into a rotation by theta per step with cos(theta) = 1 - (w h)^2 / 2; the
// discrete solution is x_n = A cos(n theta) + B sin(n theta). Its frequency error against
// w is (w h)^2 / 24 to leading order.
TEST(SingleSpring, OscillatesAsTheSchemesDiscreteSolutionAndNearTheAnalyticFrequency) {
    const Real k = 40, m = Real(0.1), rest = 1, amplitude = Real(0.05);
    const Real h = Real(1.0 / 240.0);
    SpringPhase spring;
    spring.add(0, 1, rest);
    Matrix3X x(3, 2), v = Matrix3X::Zero(3, 2), force(3, 2);
    x.col(0) = Vec3::Zero();
    x.col(1) = Vec3(0, -(rest + amplitude), 0);
    VectorX inv_mass(2);
    inv_mass << 0, 1 / m;
    const double w = std::sqrt(double(k / m));
    const double theta = std::acos(1 - w * w * double(h) * double(h) / 2);
    // Discrete solution from x_0 = A and x_1 = x_0 + h v_1 with v_1 = -h w^2 x_0.
    const double a = amplitude;
    const double x1 = a * (1 - w * w * double(h) * double(h));
    const double b = (x1 - a * std::cos(theta)) / std::sin(theta);
    int crossings = 0;
    double first_crossing = 0, last_crossing = 0, previous = a;
    const int steps = 2400;
    for (int n = 1; n <= steps; ++n) {
        force.setZero();
        add_spring_forces(spring, k, x, force);
        integrate_particles(x, v, inv_mass, force, 2, 1, 0, BodyMotion{}, Vec3::Zero(), h);
        const double stretch = -double(x(1, 1)) - double(rest);
        ASSERT_NEAR(stretch, a * std::cos(n * theta) + b * std::sin(n * theta), 2e-4 * a) << "step " << n;
        if ((previous > 0) != (stretch > 0)) {
            const double t = (n - 1 + previous / (previous - stretch)) * double(h);
            if (crossings == 0) first_crossing = t;
            last_crossing = t;
            ++crossings;
        }
        previous = stretch;
    }
    ASSERT_GE(crossings, 4);
    const double period = 2 * (last_crossing - first_crossing) / (crossings - 1);
    const double analytic = 2 * std::numbers::pi / w;
    const double known_error = (w * double(h)) * (w * double(h)) / 24;
    EXPECT_NEAR(period / analytic, 1.0, 1.5 * known_error + 1e-4);
}

TEST(Stability, ClassicNeedsASmallerStepThanSimplifiedForTheSameMaterial) {
    RectangleParams params;
    const Garment g = *make_rectangle(params);
    const Real simplified = stable_step_s(*g.fabric, g.config.material, g.state.inv_mass, ClothModel::simplified);
    const Real classic = stable_step_s(*g.fabric, g.config.material, g.state.inv_mass, ClothModel::classic);
    EXPECT_GT(simplified, classic);
    // A single spring and a fixed end: the bound is the textbook 2 sqrt(m / k).
    Fabric t;
    t.layer = {1, 1};
    t.layer1_count = 2;
    t.warp1.add(0, 1, 1);
    ClothMaterial material;
    material.drag_N_s_m = 0;
    VectorX inv_mass(2);
    inv_mass << 0, 4;  // m = 0.25 kg
    EXPECT_NEAR(stable_step_s(t, material, inv_mass, ClothModel::classic), 2 * std::sqrt(0.25 / material.stretch_k_N_m),
                1e-5);
}

}  // namespace
}  // namespace drape
