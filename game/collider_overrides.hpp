// Collider overrides of a scene (docs/scenes.md, "colliders"): reshape the ellipsoid(s)
// fitted to one bone of a character, add one where the bone has none, or remove them.
// Applied after the character is spawned and before it is dressed, so that garments fit
// around the overridden body.
#pragma once

#include <cstddef>
#include <span>

#include "drape/engine/assets/character_asset.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/game/scene_description.hpp"

namespace drape {

/// Applies the overrides for the scene's character number `index` (spawned as `character`
/// from `asset`); overrides of other characters are skipped. The error names the override
/// ("colliders[1].bone: no bone \"Tail\" in avatar.glb (bones: ...)") with its place in the
/// scene file.
[[nodiscard]] Result<void> apply_collider_overrides(Registry& registry, Entity character, std::size_t index,
                                                    std::span<const ColliderOverride> overrides, const CharacterAsset& asset);

}  // namespace drape
