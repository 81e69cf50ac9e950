// Forces and time integration of the mass-spring garment (method §3.3, §3.4).
//
// Step order of one substep (cloth integration system):
//   1. F_springs: Hooke forces of the stretch springs (simplified: the stretch springs
//      joining layer-1 particles, along the warp and to the next layer-1 line along the
//      weft; classic: warp, weft, shear and bend springs on the full grid).
//   2. Per free particle, the force of paper eq. 2 in the frame of the body (the anchor
//      collider translating with velocity v_b and acceleration a_b at the particle):
//          F = -m a_b - k (v_b + a_b h/2) - k v_rel + m g + F_springs,  v_rel = v - v_b.
//   3. Symplectic Euler (§3.4) on world velocities: the body frame itself accelerates by
//      a_b, so the world velocity changes by h (F/m + a_b); then x += h v.
// All terms use time-t values (explicit scheme). Pinned particles (inv_mass 0) are left to
// the pins.
#pragma once

#include "components/garment.hpp"
#include "engine/core/math.hpp"

namespace drape {

/// Adds the Hooke forces of `springs` (stiffness k, N/m) to `force` (one column per particle).
void add_spring_forces(const SpringPhase& springs, Real k_N_m, const Matrix3X& x, Matrix3X& force);

/// Rigid motion of the body part that carries the garment (method §3.3).
struct BodyMotion {
    Vec3 center = Vec3::Zero();                  ///< A point of the body part, m.
    Vec3 velocity_m_s = Vec3::Zero();            ///< Of that point.
    Vec3 acceleration_m_s2 = Vec3::Zero();
    Vec3 angular_velocity_rad_s = Vec3::Zero();
};

/// Paper eq. 2 and symplectic Euler on particles [0, count). `mass_scale` multiplies the
/// mass and drag of each particle (a layer-1 particle stands for its weft neighbours);
/// `force` must already hold F_springs for the same scale.
void integrate_particles(Matrix3X& x, Matrix3X& v, const VectorX& inv_mass, const Matrix3X& force,
                         Eigen::Index count, Real mass_scale, Real drag_N_s_m, const BodyMotion& body,
                         const Vec3& gravity_m_s2, Real h_s);

/// Largest stable explicit step (method §3.4) of the garment under `model`: h = 2 / sqrt(lambda)
/// with lambda the Gershgorin bound of M^-1 K over the integrated particles (each spring
/// adds k to both ends' rows, twice when the other end moves too), also kept below m / k_drag.
[[nodiscard]] Real stable_step_s(const Fabric& topology, const ClothMaterial& material,
                                 const VectorX& inv_mass, ClothModel model);

}  // namespace drape
