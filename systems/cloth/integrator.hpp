// The explicit part of the garment's motion (method §3.3, §3.4): paper eq. 2 without its
// spring term (the springs are constraints, constraints.hpp), integrated by symplectic
// Euler relative to the frame of the body part the garment hangs from.
//
// Conventions
// - The anchor frame is the anchor collider's rigid frame (rotation R, centre c). Over a
//   fixed step it moves with velocity V and angular velocity W (constant over the step;
//   V_prev and W_prev when the particles' velocities were last written); over a substep it
//   goes from (R0, c0) to (R1, c1).
// - A particle's place and velocity relative to the frame: r = R0^T (x - c0),
//   u = R0^T (v - V_prev - W_prev x (x - c0)). Paper eq. 2 in that frame:
//       m du/dt = -m s_lin a_b - k (v - v_air) + m g
//                 - m s_ang (2 W x u + W x (W x r) + dW/dt x r)
//   with k the particle's air drag (material drag per area x its area) and the inertia
//   scales s_lin, s_ang (InertiaScales: 1 is physical, 0 carries the particle rigidly with
//   the frame). The air moves with the share of the frame's motion the particle does not
//   feel, v_air = (1 - s_lin) V + (1 - s_ang) W x (x - c0): still air at 1, the frame's own
//   motion at 0 (so that a garment at rest on a body that only moves stays at rest on it).
//   The paper's drag, -k (v_b + a_b h/2) - k v_rel, is -k (v + a_b h/2) with both scales 1:
//   its a_b h/2 is a step-size artefact (a force that depends on the body's acceleration
//   and on h), left out here. The frame's velocity changes once per fixed step, so the
//   inertial terms -m s_lin a_b and -m s_ang dW/dt x r act as the impulse
//   -s_lin (V - V_prev) - s_ang (W - W_prev) x (x - c0) at the step's first substep.
//   With a bound on the felt acceleration (InertiaScales::max_linear_m_s2 > 0) a step whose
//   s_lin |a_b| exceeds it takes s_lin x bound / (s_lin |a_b|) as its linear scale. With a
//   fall bound (InertiaScales::max_fall_m_s2 > 0) a step whose felt acceleration along
//   gravity, s_lin a_b . d (d = g / |g|; a_b over the last two fixed steps,
//   (V - V_earlier) / 2 step, where the step is given), exceeds it feels that part scaled by
//   bound / (s_lin a_b . d) more: the impulse's and the air's parts along d take
//   s_fall = s_lin bound / (s_lin a_b . d), their other parts s_lin.
// - Symplectic Euler: u += h du/dt, r += h u; then back to the world with the frame at the
//   end of the substep: x = R1 r + c1, v = R1 u + V + W x (x - c1). With both scales 1 this
//   is the world-frame motion, and it is integrated in the world directly (the same scheme,
//   v += h dv/dt, x += h v, without the frame changes); with 0 a particle at rest in the
//   frame stays at rest in it.
// Pinned particles (inverse mass 0) are left to the pins.
#pragma once

#include <span>

#include "drape/components/garment.hpp"
#include "drape/engine/core/math.hpp"
#include "drape/systems/cloth/constraints.hpp"

namespace drape {

/// The anchor's rigid motion over one substep.
struct AnchorMotion {
    Mat3 r0 = Mat3::Identity(), r1 = Mat3::Identity();  ///< Rotation at the start and end of the substep.
    Vec3 c0 = Vec3::Zero(), c1 = Vec3::Zero();          ///< Centre at the start and end.
    Vec3 velocity_m_s = Vec3::Zero();                   ///< V.
    Vec3 angular_velocity_rad_s = Vec3::Zero();         ///< W.
    Vec3 velocity_before_m_s = Vec3::Zero();            ///< V_prev.
    Vec3 velocity_earlier_m_s = Vec3::Zero();           ///< V one step before V_prev (InertiaScales::max_fall_m_s2 with step_s > 0).
    Vec3 angular_velocity_before_rad_s = Vec3::Zero();  ///< W_prev.
    Real step_s = 0;                                    ///< The fixed step V - V_prev spans; > 0: the fall bound's acceleration is (V - V_earlier) / (2 step_s).
    Vec3 acceleration_m_s2 = Vec3::Zero();              ///< a_b; read only for InertiaScales::max_linear_m_s2 and max_fall_m_s2 (its inertial term acts through V - V_prev, and the drag no longer takes a_b h/2: docs/cloth.md, Integration).
};

/// Prediction of particles [first, end): `drag` is each particle's k (N s/m).
void predict_particles(Matrix3X& x, Matrix3X& v, const VectorX& inv_mass, const VectorX& drag_N_s_m,
                       Eigen::Index first, Eigen::Index end, const AnchorMotion& anchor, const InertiaScales& inertia,
                       const Vec3& gravity_m_s2, Real h_s);

/// Eq. 2's spring term (method §3.3), for the paper's integrator: Hooke's force
/// k (|d| - L) d / |d| of each spring of `set` (k = 1 / its compliance) at positions `x`,
/// given to both ends' velocities as h F inv_mass (pinned ends, inverse mass 0, keep theirs).
/// Added before predict_particles, whose velocity update then takes the rest of eq. 2: the
/// spring force at the start of the step, symplectic Euler (method §3.4).
void add_spring_impulses(const SpringSet& set, const Matrix3X& x, const VectorX& inv_mass, Real h_s, Matrix3X& v);

/// Largest step for which symplectic Euler on the springs of `sets` listed in `which` stays
/// bounded (method §3.4):
/// 2 / sqrt(lambda), lambda a bound on the largest eigenvalue of M^-1 K (Gershgorin on
/// M^-1/2 K M^-1/2: over the particles, sum of k / m_i + sum of k / sqrt(m_i m_j) over its
/// springs; a stretched spring's sideways stiffness is below k). +inf without springs.
[[nodiscard]] Real spring_step_limit_s(std::span<const SpringSet> sets, std::span<const std::size_t> which,
                                       const VectorX& inv_mass);

/// Largest step for which the explicit drag of eq. 2 stays stable: min over particles of m / k.
[[nodiscard]] Real drag_step_limit_s(const VectorX& inv_mass, const VectorX& drag_N_s_m, Eigen::Index count);

}  // namespace drape
