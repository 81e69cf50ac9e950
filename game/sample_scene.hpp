// The sample scene: Drape's default avatar walking in place in the paper's skirt, what
// `drape play` plays with no scene named.
#pragma once

#include <filesystem>

#include "drape/game/scene_description.hpp"

namespace drape {

/// The sample scene: the default avatar walking in place in a skirt. The same as
/// assets/scenes/sample.json.
[[nodiscard]] SceneDescription sample_scene();

/// `scene` with `file` as its first character (added when it has none): its own clips (the
/// clip name cleared, which meant nothing to another file) and none of the collider overrides
/// that named the former character's bones. What `--character FILE` does for play,
/// export-garment and make-garments.
void use_character_file(SceneDescription& scene, const std::filesystem::path& file);

}  // namespace drape
