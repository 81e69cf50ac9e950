// The characters and clips the benchmarks dress: the default avatar and every character
// file under ../shared/assets/characters, and of each the clips a game plays a garment on.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "drape/engine/assets/character_asset.hpp"

namespace drape::bench {

/// A character file, named as the reports name it.
struct CharacterFile {
    std::string name;
    std::filesystem::path file;
    bool default_avatar = false;
};

/// The default avatar, then the shared characters' .fbx, .glb and .gltf files, sorted.
[[nodiscard]] std::vector<CharacterFile> character_files();

/// `s` in lower case (ASCII).
[[nodiscard]] std::string lower(std::string s);

/// Whether a case's `name` holds every comma-separated word of `filter` (any case; an empty
/// filter keeps every case): `drape bench NAME --filter WORDS`.
[[nodiscard]] bool matches_filter(const std::string& name, const std::string& filter);

/// The kind of motion a clip's name says, among those a game plays a garment on (walk,
/// run, jump, running jump, idle, attack, sitting, death); "" for others (swimming,
/// rolling, clapping, ...).
[[nodiscard]] std::string clip_kind(const std::string& full_name);

/// One clip per kind (the first in the file whose name names no direction or variant, else the
/// first), in the order walk, run, jump, running jump, idle, attack, sitting, death.
[[nodiscard]] std::vector<std::pair<std::string, const AnimationClip*>> chosen_clips(const CharacterAsset& asset);

}  // namespace drape::bench
