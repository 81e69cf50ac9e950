// Explicit prediction in the anchor frame (method §3.3, §3.4); conventions in integrator.hpp.
#include "drape/systems/cloth/integrator.hpp"

#include <algorithm>
#include <limits>

namespace drape {

void predict_particles(Matrix3X& x, Matrix3X& v, const VectorX& inv_mass, const VectorX& drag,
                       Eigen::Index first, Eigen::Index end, const AnchorMotion& f, const InertiaScales& inertia,
                       const Vec3& g, Real h) {
    if (inertia.linear == 1 && inertia.angular == 1) {
        // The particles feel all of the frame's motion: its inertial and fictitious forces
        // cancel the frame's own motion, and the motion in the frame is the motion in the
        // world. Integrated there directly: the same scheme without the frame changes.
        const Vec3 drag_body_offset = f.acceleration_m_s2 * (h / 2);  // eq. 2: v_b + a_b h / 2
        for (Eigen::Index i = first; i < end; ++i) {
            const Real inv_m = inv_mass[i];
            if (inv_m == 0) continue;  // pinned: follows the skin (method §3.5)
            const Vec3 vi = v.col(i);
            const Vec3 v_new = vi + h * (g - (drag[i] * inv_m) * (vi + drag_body_offset));
            v.col(i) = v_new;
            x.col(i) += h * v_new;
        }
        return;
    }
    const Mat3 r0t = f.r0.transpose();
    const Vec3 w = f.angular_velocity_rad_s, w_before = f.angular_velocity_before_rad_s;
    const Vec3 w_local = r0t * w;
    // The inertial impulse of the frame's change of motion since the velocities were written.
    const Vec3 linear_kick = inertia.linear * (f.velocity_m_s - f.velocity_before_m_s);
    const Vec3 angular_kick = inertia.angular * (w - w_before);
    const Vec3 drag_body_offset = f.acceleration_m_s2 * (h / 2);  // eq. 2: v_b + a_b h / 2
    const Real s_ang = inertia.angular;
    for (Eigen::Index i = first; i < end; ++i) {
        const Real inv_m = inv_mass[i];
        if (inv_m == 0) continue;  // pinned: follows the skin (method §3.5)
        const Vec3 vi = v.col(i);
        const Vec3 d = x.col(i) - f.c0;
        const Vec3 r = r0t * d;
        Vec3 u = r0t * (vi - f.velocity_before_m_s - w_before.cross(d) - linear_kick - angular_kick.cross(d));
        // Drag: -k (v_b + a_b h/2) - k (v - v_b) = -k (v + a_b h/2), in the world.
        const Vec3 forces = g - (drag[i] * inv_m) * (vi + drag_body_offset);
        const Vec3 fictitious = s_ang * (2 * w_local.cross(u) + w_local.cross(w_local.cross(r)));
        u += h * (r0t * forces - fictitious);
        const Vec3 x_new = f.r1 * (r + h * u) + f.c1;
        x.col(i) = x_new;
        v.col(i) = f.r1 * u + f.velocity_m_s + w.cross(x_new - f.c1);
    }
}

Real drag_step_limit_s(const VectorX& inv_mass, const VectorX& drag, Eigen::Index count) {
    Real h = std::numeric_limits<Real>::infinity();
    for (Eigen::Index i = 0; i < count; ++i)
        if (inv_mass[i] != 0 && drag[i] > 0) h = std::min(h, 1 / (inv_mass[i] * drag[i]));
    return h;
}

}  // namespace drape
