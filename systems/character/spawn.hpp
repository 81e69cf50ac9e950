// Putting a character into a scene: one entity with Character, Transform, Skeleton,
// SkinnedMesh and AnimationPlayer, and one entity per EllipsoidCollider pointing back at it.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/transform.hpp"
#include "drape/engine/assets/character_asset.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/character/character_body.hpp"

namespace drape {

struct SpawnOptions {
    Transform transform;
    std::string clip;                  ///< Name or index; empty = choose_default_clip() (a walk when there is one; no clips: rest pose).
    double speed = 1;                  ///< Playback rate.
    /// Whether the clip loops; unset: when clip_loops() says so (its first and last poses within
    /// 15 degrees), else it plays once and holds its last pose (a fall, a sit, a jump).
    std::optional<bool> loop;
    bool in_place = true;              ///< false: root motion moves the Transform.
    double start_time_s = 0;           ///< Where in the clip to start.
    std::vector<EllipsoidShape> collider_overrides;  ///< Replace the fitted ellipsoids of their bones (or add).
    bool replace_fitted_colliders = false;           ///< Use only the overrides.
};

/// Creates the character and its colliders (the body's ellipsoids with the overrides
/// applied), posed at the start time and skinned, so they are valid before the first
/// step. `body` is fit_character_body(*asset) or one the caller made. Errors name the
/// character's file and the field.
[[nodiscard]] Result<Entity> spawn_character(Registry& registry, std::shared_ptr<const CharacterAsset> asset,
                                             const CharacterBody& body, const SpawnOptions& options = {});

/// The collider entities of a character.
[[nodiscard]] std::vector<Entity> colliders_of(Registry& registry, Entity character);

/// Destroys a character and its colliders.
void despawn_character(Registry& registry, Entity character);

}  // namespace drape
