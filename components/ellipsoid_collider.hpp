// One ellipsoid bound to a skeleton bone (method §2, §5): a unit sphere scaled by `radii`,
// rotated and placed in bone space; it follows its bone.
#pragma once

#include "engine/core/math.hpp"
#include "engine/core/registry.hpp"

namespace drape {

struct EllipsoidCollider {
    // Authored or fitted, in the bone's space (metres).
    Entity character;                        ///< The entity with the Skeleton and Transform.
    int bone = -1;
    Vec3 center = Vec3::Zero();
    Quat rotation = Quat::Identity();
    Vec3 radii_m = Vec3::Constant(0.1f);

    // World state, written by the collider system once per fixed step.
    Affine3 world = Affine3::Identity();           ///< Unit sphere -> world (translation * rotation * scale).
    Affine3 previous_world = Affine3::Identity();  ///< The same one fixed step earlier (for substep interpolation).
    Vec3 velocity_m_s = Vec3::Zero();              ///< Of the centre, finite difference over a step.
    Vec3 acceleration_m_s2 = Vec3::Zero();         ///< Of the centre.
    Vec3 angular_velocity_rad_s = Vec3::Zero();    ///< Of the ellipsoid frame.
    bool initialised = false;                      ///< False until the first update (no velocity yet).
};

}  // namespace drape
