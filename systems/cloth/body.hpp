// The body as the cloth sees it: ellipsoid colliders at a point of the fixed step, and the
// rigid motion of the garment's anchor (method §2, §3.3, §5).
//
// Conventions: a collider's `world` maps the unit sphere to world space as
// translation * rotation * scale (no shear). Within a fixed step the cloth takes several
// substeps; a collider at fraction alpha of the step is interpolated between
// `previous_world` (alpha 0) and `world` (alpha 1): centre and radii linearly, rotation by
// slerp. Velocity, acceleration and angular velocity are the collider system's, constant
// over the step.
#pragma once

#include <span>
#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/systems/cloth/garment_solver.hpp"
#include "drape/engine/core/math.hpp"
#include "drape/engine/core/registry.hpp"

namespace drape {

/// A frame from a unit-sphere -> world transform (translation * rotation * scale).
[[nodiscard]] EllipsoidFrame make_ellipsoid_frame(const Affine3& unit_to_world);

/// The collider at fraction `alpha` in [0, 1] of the current fixed step.
[[nodiscard]] EllipsoidFrame interpolate_collider(const EllipsoidCollider& collider, Real alpha);

/// Unit-sphere -> world transform of a frame.
[[nodiscard]] Affine3 unit_to_world(const EllipsoidFrame& frame);

/// Refreshes `frames` (one per entry of `body.colliders`) at `alpha`.
/// A collider whose entity is gone becomes inactive. No allocation once sized.
void update_frames(const Registry& registry, const GarmentBody& body, std::vector<EllipsoidFrame>& frames, Real alpha);

/// Rigid frame (rotation + centre, no scale) of the anchor collider among `frames`, or identity.
[[nodiscard]] Affine3 anchor_frame(std::span<const EllipsoidFrame> frames, std::int32_t anchor);

/// Arms and hands hang outside a garment: a free particle inside an arm's or a hand's
/// ellipsoid (of `frames`, one per entry of `body.colliders`), on the limb's far side from
/// the anchor's centre, goes in, level (world up is +y), toward that centre until it is
/// outside every arm and hand, so that the collision that follows does not wrap the cloth
/// round the limb. For a rest shape put round a body in some pose (placement, reset).
void tuck_under_limbs(const Registry& registry, const GarmentBody& body, std::span<const EllipsoidFrame> frames, Matrix3X& x,
                      const VectorX& inv_mass);

/// Velocity of the body point at `x` carried by `frame`'s rigid motion: v_c + w x (x - c).
[[nodiscard]] inline Vec3 body_velocity_at(const EllipsoidFrame& frame, const Vec3& x) {
    return frame.velocity_m_s + frame.angular_velocity_rad_s.cross(x - frame.center);
}

}  // namespace drape
