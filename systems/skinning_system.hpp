// The skinning system (phase render, before the render system; method §1.2): linear blend
// skinning of every character's mesh into world space (its Transform applied), once per
// drawn frame, in parallel over characters (and over vertex blocks for big meshes).
//
// Only a world that draws adds it (game/world.cpp): the simulation needs the bones, not
// the mesh. Colliders follow their bones (systems/collider_system.hpp) and pinned
// particles are skinned from Skeleton::skinning (systems/cloth/pins.hpp), so a headless
// world skins no vertex after spawning. Every skinned vertex is counted in
// SkinnedMesh::skinned_vertices.
#pragma once

#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"

namespace drape {

[[nodiscard]] System make_skinning_system();

/// Skins every character's mesh (Skeleton + SkinnedMesh) at its current pose, in parallel
/// over characters: the system's run, for callers without a scheduler.
void skin_characters(Registry& registry);

}  // namespace drape
