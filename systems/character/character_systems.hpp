// The character systems in their order: animation (phase animation), then skinning and
// colliders (phase skinning, colliders after skinning).
#pragma once

#include "engine/core/scheduler.hpp"

namespace drape {

/// Adds animation, skinning and collider systems to a scheduler.
void add_character_systems(Scheduler& scheduler);

}  // namespace drape
