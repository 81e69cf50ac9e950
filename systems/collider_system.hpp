// The collider system (phase skinning, after skinning; method §1.3, §2, §3.3): moves
// every EllipsoidCollider with its bone, world = Transform * rigid(bone global) * local,
// keeps the previous world transform, and differentiates the centre over the fixed step
// for the velocity and acceleration the body-driven force model needs, plus the frame's
// angular velocity. The first update gives zero velocity and acceleration; the second
// gives a velocity and still zero acceleration. Colliders are updated in parallel.
#pragma once

#include "engine/core/scheduler.hpp"

namespace drape {

struct EllipsoidCollider;
struct Skeleton;
struct Transform;

[[nodiscard]] System make_collider_system();

/// One collider's update from its character's pose (tests call it without a scheduler).
void update_collider(EllipsoidCollider& collider, const Skeleton& skeleton, const Transform* transform, double dt_s);

}  // namespace drape
