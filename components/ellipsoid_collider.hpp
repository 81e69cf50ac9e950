// One ellipsoid bound to a skeleton bone (method §2, §5): a unit sphere scaled by `radii`,
// rotated and placed in bone space; it follows its bone.
//
// "Bone space" here is the bone's frame with any scale removed (its position and
// orientation only), so centres and radii are in metres even when a file's armature
// carries a scale: world = Transform * rigid(bone global) * translate(center) *
// rotate(rotation) * scale(radii_m).
#pragma once

#include <cstdint>
#include <string>

#include "drape/engine/core/math.hpp"
#include "drape/engine/core/registry.hpp"

namespace drape {

/// The part of a body an ellipsoid covers, guessed from bone names (the skirt builder
/// looks for `pelvis`, a shirt for `torso` and the arms).
enum class BodyRegion : std::uint8_t {
    other, head, neck, torso, pelvis, upper_arm, lower_arm, hand, upper_leg, lower_leg, foot,
};
[[nodiscard]] const char* body_region_name(BodyRegion region) noexcept;

/// An upper arm, a forearm or a hand.
[[nodiscard]] constexpr bool is_arm(BodyRegion r) noexcept {
    return r == BodyRegion::upper_arm || r == BodyRegion::lower_arm || r == BodyRegion::hand;
}

/// A thigh, a shin or a foot.
[[nodiscard]] constexpr bool is_leg(BodyRegion r) noexcept {
    return r == BodyRegion::upper_leg || r == BodyRegion::lower_leg || r == BodyRegion::foot;
}

/// What a skirt or a dress leaves outside: the arms and the head.
[[nodiscard]] constexpr bool hangs_outside_garments(BodyRegion r) noexcept { return is_arm(r) || r == BodyRegion::head; }

/// An ellipsoid in bone space: what fitting produces and a scene file may override.
struct EllipsoidShape {
    int bone = -1;                     ///< Index into SkeletonAsset.
    Vec3 center = Vec3::Zero();        ///< m, bone space.
    Quat rotation = Quat::Identity();  ///< Bone space -> ellipsoid axes.
    Vec3 radii_m = Vec3::Constant(0.1f);
    BodyRegion region = BodyRegion::other;
    Real give_m = 0;                   ///< See EllipsoidCollider::give_m.
};

struct EllipsoidCollider {
    // Authored or fitted, in the bone's space (metres).
    Entity character;                        ///< The entity with the Skeleton and Transform.
    int bone = -1;
    Vec3 center = Vec3::Zero();
    Quat rotation = Quat::Identity();
    Vec3 radii_m = Vec3::Constant(0.1f);
    BodyRegion region = BodyRegion::other;
    /// How deep cloth may lie inside this ellipsoid where it meets one that does not give,
    /// m (0: none). Where a forearm's or a hand's ellipsoid overlaps the hips' but its skin
    /// does not, cloth caught between them keeps to the ellipsoid that does not give. The
    /// fit gives forearms and hands their bulge over the skin (ellipsoid_fit.hpp).
    Real give_m = 0;

    // World state, written by the collider system once per fixed step.
    Affine3 world = Affine3::Identity();           ///< Unit sphere -> world (translation * rotation * scale).
    Affine3 previous_world = Affine3::Identity();  ///< The same one fixed step earlier (for substep interpolation).
    Vec3 velocity_m_s = Vec3::Zero();              ///< Of the centre, finite difference over a step.
    Vec3 acceleration_m_s2 = Vec3::Zero();         ///< Of the centre.
    Vec3 angular_velocity_rad_s = Vec3::Zero();    ///< Of the ellipsoid frame.
    bool initialised = false;                      ///< False until the first update (no velocity yet).
    bool placed = false;                           ///< `world` holds the bone's pose: set by spawn_character and every update.
    Quat world_rotation = Quat::Identity();        ///< Rotation part of `world` (ellipsoid axes in world space).
    std::uint8_t updates = 0;                      ///< Updates so far, saturating at 2: velocity needs 1, acceleration 2.
};

}  // namespace drape
