// One character's animation update (method §1.1), as the animation system
// (systems/animation_system.hpp) runs it for every character: advance the player by the
// step, sample its clip (lerp, slerp), compose the pose down the hierarchy and keep
// Skeleton::skinning = global * inverse_bind current. Root motion (in_place = false)
// advances the Transform by the clip's travel each time the clip loops.
#pragma once

namespace drape {

struct AnimationPlayer;
struct Skeleton;
struct Transform;

/// One entity's update (tests call it without a scheduler).
void advance_animation(AnimationPlayer& player, Skeleton& skeleton, Transform* transform, double dt_s);

}  // namespace drape
