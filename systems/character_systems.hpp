// The character systems a simulation needs, in their order: animation (phase animation),
// then colliders (phase skinning: they follow their bones). Skinning the mesh is for
// drawing: the skinning system (systems/skinning_system.hpp) runs in the render phase of
// a world that renders.
#pragma once

#include "drape/engine/core/scheduler.hpp"

namespace drape {

/// Adds the animation and collider systems to a scheduler.
void add_character_systems(Scheduler& scheduler);

}  // namespace drape
