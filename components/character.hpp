// A character: the entity that owns a skeleton, a skin, an animation player and a
// transform; its ellipsoid colliders and garments point back to it.
#pragma once

#include <memory>
#include <string>

#include "drape/engine/core/math.hpp"

namespace drape {

struct CharacterAsset;  // engine/assets/character_asset.hpp: what the importer produced.

struct Character {
    std::string name;
    std::shared_ptr<const CharacterAsset> asset;
    Real height_m = 0;   ///< Standing height of the body (BodyLandmarks::height_m; without landmarks, the file's rest pose).
};

}  // namespace drape
