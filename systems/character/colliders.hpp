// One ellipsoid collider's update from its character's pose (method §1.3, §2, §3.3), as
// the collider system (systems/collider_system.hpp) runs it for every collider:
// world = Transform * rigid(bone global) * local, the previous world transform kept, and
// the centre differentiated over the fixed step for the velocity and acceleration the
// body-driven force model needs, plus the frame's angular velocity. The first update
// gives zero velocity and acceleration; the second a velocity and still zero acceleration.
#pragma once

namespace drape {

struct EllipsoidCollider;
struct Skeleton;
struct Transform;

/// One collider's update (tests call it without a scheduler).
void update_collider(EllipsoidCollider& collider, const Skeleton& skeleton, const Transform* transform, double dt_s);

}  // namespace drape
