// One collider's update: see colliders.hpp.
#include "drape/systems/character/colliders.hpp"

#include <cmath>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/systems/character/pose.hpp"

namespace drape {

void update_collider(EllipsoidCollider& c, const Skeleton& skeleton, const Transform* transform, double dt_s) {
    if (c.bone < 0 || static_cast<std::size_t>(c.bone) >= skeleton.global.size()) return;
    const Affine3 to_world = transform ? transform->matrix() : Affine3::Identity();
    const Affine3 bone = rigid_part(to_world) * rigid_part(skeleton.global[static_cast<std::size_t>(c.bone)]);
    const Real world_scale = transform ? transform->scale : Real(1);
    Affine3 local = Affine3::Identity();
    local.translate(c.center * world_scale);
    local.rotate(c.rotation);
    local.scale(c.radii_m * world_scale);
    const Affine3 world = bone * local;
    const Quat rotation = (Quat(bone.linear()) * c.rotation).normalized();

    const bool differentiate = c.initialised && dt_s > 0;
    const Vec3 velocity = differentiate ? Vec3((world.translation() - c.world.translation()) / Real(dt_s)) : Vec3::Zero();
    Vec3 acceleration = Vec3::Zero();
    Vec3 angular = Vec3::Zero();
    if (differentiate) {
        if (c.updates >= 2) acceleration = (velocity - c.velocity_m_s) / Real(dt_s);
        // Rotation over the step as axis * angle, the shorter way round.
        Quat delta = rotation * c.world_rotation.conjugate();
        if (delta.w() < 0) delta.coeffs() *= -1;
        const Real s = delta.vec().norm();
        const Real angle = 2 * std::atan2(s, delta.w());
        angular = s > Real(1e-9) ? Vec3(delta.vec() * (angle / (s * Real(dt_s)))) : Vec3(delta.vec() * (2 / Real(dt_s)));
    }
    if (!velocity.allFinite() || !acceleration.allFinite() || !angular.allFinite()) return;  // keep the last good state
    c.previous_world = c.initialised ? c.world : world;
    c.world = world;
    c.world_rotation = rotation;
    c.velocity_m_s = velocity;
    c.acceleration_m_s2 = acceleration;
    c.angular_velocity_rad_s = angular;
    c.initialised = true;
    c.placed = true;
    if (c.updates < 2) ++c.updates;
}

}  // namespace drape
