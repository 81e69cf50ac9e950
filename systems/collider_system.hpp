// The collider system (phase skinning, after skinning; method §1.3, §2, §3.3): moves
// every EllipsoidCollider with its bone, world = Transform * rigid(bone global) * local,
// keeps the previous world transform, and differentiates the centre over the fixed step
// for the velocity and acceleration the body-driven force model needs, plus the frame's
// angular velocity. The first update gives zero velocity and acceleration; the second
// gives a velocity and still zero acceleration. Colliders are updated in parallel.
#pragma once

#include "drape/engine/core/scheduler.hpp"

namespace drape {

[[nodiscard]] System make_collider_system();  ///< update_collider (systems/character/colliders.hpp) for every collider.

}  // namespace drape
