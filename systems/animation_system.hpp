// The animation system (phase animation, method §1.1): advances each AnimationPlayer by
// the fixed step, samples its clip (lerp, slerp), composes the pose down the hierarchy
// and keeps Skeleton::skinning = global * inverse_bind current, so the cloth can skin its
// pinned particles without the mesh. Root motion (AnimationPlayer::in_place = false)
// advances the Transform by the clip's travel each time the clip loops. Characters are
// posed in parallel.
#pragma once

#include "drape/engine/core/scheduler.hpp"

namespace drape {

[[nodiscard]] System make_animation_system();  ///< advance_animation (systems/character/animation.hpp) for every character.

}  // namespace drape
