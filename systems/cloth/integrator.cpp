// Explicit prediction in the anchor frame (method §3.3, §3.4); conventions in integrator.hpp.
#include "drape/systems/cloth/integrator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {

void predict_particles(Matrix3X& x, Matrix3X& v, const VectorX& inv_mass, const VectorX& drag,
                       Eigen::Index first, Eigen::Index end, const AnchorMotion& f, const InertiaScales& inertia,
                       const Vec3& g, Real h) {
    // The felt acceleration's bound (InertiaScales::max_linear_m_s2): as the scale that
    // brings the anchor's felt acceleration to it, for the whole fixed step.
    Real s_lin = inertia.linear;
    const Real felt = s_lin * f.acceleration_m_s2.norm();
    if (inertia.max_linear_m_s2 > 0 && felt > inertia.max_linear_m_s2) s_lin *= inertia.max_linear_m_s2 / felt;
    // The fall bound (InertiaScales::max_fall_m_s2): the scale s_fall of the felt
    // acceleration's part along gravity where it points down faster than the bound, for the
    // whole fixed step; the other parts keep s_lin.
    Real s_fall = s_lin;
    Vec3 down = Vec3::Zero();
    if (inertia.max_fall_m_s2 > 0 && g.squaredNorm() > 0) {
        down = g.normalized();
        // Over the last two fixed steps where they are known: a clip keyed at 30 Hz and played
        // at 60 moves its root every other step, whose one-step acceleration is then twice
        // the motion's (a walk's hips at 2 g on one step and 0 on the next).
        const Vec3 a = f.step_s > 0 ? Vec3((f.velocity_m_s - f.velocity_earlier_m_s) / (2 * f.step_s)) : f.acceleration_m_s2;
        const Real falling = s_lin * a.dot(down);
        if (falling > inertia.max_fall_m_s2) s_fall = s_lin * inertia.max_fall_m_s2 / falling;
    }
    if (s_lin == 1 && s_fall == 1 && inertia.angular == 1) {
        // The particles feel all of the frame's motion: its inertial and fictitious forces
        // cancel the frame's own motion, and the motion in the frame is the motion in the
        // world. Integrated there directly: the same scheme without the frame changes.
        // Still air: the drag acts on the world velocity.
        for (Eigen::Index i = first; i < end; ++i) {
            const Real inv_m = inv_mass[i];
            if (inv_m == 0) continue;  // pinned: follows the skin (method §3.5)
            const Vec3 vi = v.col(i);
            const Vec3 v_new = vi + h * (g - (drag[i] * inv_m) * vi);
            v.col(i) = v_new;
            x.col(i) += h * v_new;
        }
        return;
    }
    const Mat3 r0t = f.r0.transpose();
    const Vec3 w = f.angular_velocity_rad_s, w_before = f.angular_velocity_before_rad_s;
    const Vec3 w_local = r0t * w;
    // The inertial impulse of the frame's change of motion since the velocities were written.
    // Felt: s_lin of the change, s_fall of its part along gravity under the fall bound.
    const Vec3 change = f.velocity_m_s - f.velocity_before_m_s;
    Vec3 linear_kick = s_lin * change;
    if (s_fall != s_lin) linear_kick += ((s_fall - s_lin) * change.dot(down)) * down;
    const Vec3 angular_kick = inertia.angular * (w - w_before);
    const Real s_ang = inertia.angular;
    Vec3 air_linear = (1 - s_lin) * f.velocity_before_m_s;
    if (s_fall != s_lin) air_linear -= ((s_fall - s_lin) * f.velocity_before_m_s.dot(down)) * down;
    const Vec3 air_angular = (1 - s_ang) * w_before;
    for (Eigen::Index i = first; i < end; ++i) {
        const Real inv_m = inv_mass[i];
        if (inv_m == 0) continue;  // pinned: follows the skin (method §3.5)
        const Vec3 vi = v.col(i);
        const Vec3 d = x.col(i) - f.c0;
        const Vec3 r = r0t * d;
        Vec3 u = r0t * (vi - f.velocity_before_m_s - w_before.cross(d) - linear_kick - angular_kick.cross(d));
        // Drag against the air, which moves with the share of the frame's motion the
        // particle does not feel: -k (v - (1 - s_lin) V - (1 - s_ang) W x d).
        const Vec3 forces = g - (drag[i] * inv_m) * (vi - air_linear - air_angular.cross(d));
        const Vec3 fictitious = s_ang * (2 * w_local.cross(u) + w_local.cross(w_local.cross(r)));
        u += h * (r0t * forces - fictitious);
        const Vec3 x_new = f.r1 * (r + h * u) + f.c1;
        x.col(i) = x_new;
        v.col(i) = f.r1 * u + f.velocity_m_s + w.cross(x_new - f.c1);
    }
}

void add_spring_impulses(const SpringSet& set, const Matrix3X& x, const VectorX& w, Real h, Matrix3X& v) {
    const SpringPhase& sp = *set.springs;
    const std::vector<Real>& compliance = set.compliance;
    for (std::size_t s = 0; s < sp.size(); ++s) {
        const std::uint32_t a = sp.a[s], b = sp.b[s];
        const Real wa = w[a], wb = w[b];
        if (wa == 0 && wb == 0) continue;
        const Vec3 d = x.col(b) - x.col(a);
        const Real len = d.norm();
        if (!(len > 0)) continue;
        const Vec3 impulse = (h * (len - sp.rest_m[s]) / (compliance[s] * len)) * d;  // h F on a, toward b when stretched
        v.col(a) += wa * impulse;
        v.col(b) -= wb * impulse;
    }
}

Real spring_step_limit_s(std::span<const SpringSet> sets, std::span<const std::size_t> which, const VectorX& w) {
    VectorX row = VectorX::Zero(w.size());
    for (const std::size_t k : which) {
        const SpringPhase& sp = *sets[k].springs;
        for (std::size_t s = 0; s < sp.size(); ++s) {
            const std::uint32_t a = sp.a[s], b = sp.b[s];
            const Real stiffness = 1 / sets[k].compliance[s];
            const Real across = stiffness * std::sqrt(w[a] * w[b]);
            row[a] += stiffness * w[a] + across;
            row[b] += stiffness * w[b] + across;
        }
    }
    const Real lambda = row.size() > 0 ? row.maxCoeff() : Real(0);
    return lambda > 0 ? 2 / std::sqrt(lambda) : std::numeric_limits<Real>::infinity();
}

Real drag_step_limit_s(const VectorX& inv_mass, const VectorX& drag, Eigen::Index count) {
    Real h = std::numeric_limits<Real>::infinity();
    for (Eigen::Index i = 0; i < count; ++i)
        if (inv_mass[i] != 0 && drag[i] > 0) h = std::min(h, 1 / (inv_mass[i] * drag[i]));
    return h;
}

}  // namespace drape
