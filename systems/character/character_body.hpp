// What Drape derives from an imported character for its garments (method §2): ellipsoids
// fitted to the skin, which the cloth collides with, and the pelvis bone the skirt
// builder finds the waist from. The importer (engine/assets/character_import.hpp)
// returns the file's data only; a scene fits the body once per character file and spawns
// every instance of that character with it (spawn.hpp).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "drape/components/body_landmarks.hpp"
#include "drape/components/ellipsoid_collider.hpp"
#include "drape/engine/assets/character_asset.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/systems/character/body_meshes.hpp"
#include "drape/systems/character/ellipsoid_fit.hpp"

namespace drape {

/// A character's collision body, in bone space; shared by every instance of the character.
struct CharacterBody {
    std::vector<EllipsoidShape> ellipsoids;  ///< Fitted, bone space: bone, center, rotation, radii_m.
    int hip_bone = -1;                       ///< find_hip_bone(); -1 when none.
    LegFit legs = LegFit::bounding;          ///< The leg fit fit_ellipsoids used (tight or bounding).
    std::optional<BodyLandmarks> landmarks;  ///< find_body_landmarks(); none for a body that is not a humanoid.
    std::string landmarks_error;             ///< Why there are none.
    std::vector<LeftOutMesh> left_out;       ///< Meshes not fitted: props, bases, modelled garments (body_meshes.hpp).
};

/// Fits the body of an imported character: find_hip_bone() on its skeleton; a first
/// find_body_landmarks() on the whole character to tell its body from the rest
/// (find_non_body_meshes()); then fit_ellipsoids() and find_body_landmarks() on the body's
/// meshes only (its bind mesh, rest height and clips). The error (bad options, no skeleton
/// or mesh) names the character's file and the field.
[[nodiscard]] Result<CharacterBody> fit_character_body(const CharacterAsset& character, const FitOptions& options = {});

}  // namespace drape
