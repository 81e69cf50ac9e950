// Scene files: the JSON files scene descriptions (game/scene_description.hpp) are read
// from and written to (docs/scenes.md).
//
// Errors are one line naming the file, line and column and the field path, e.g.
//   scene.json:7:21: garments[0].particles: must be an integer in [16, 250000], got -3
// Unknown fields are errors (a typo must not be silently ignored), and so are absurd
// values: non-finite numbers, zero or negative sizes, more particles than a garment may
// have (max_garment_particles, 250,000).
// Relative paths resolve against the scene file's folder.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <utility>

#include "drape/engine/core/error.hpp"
#include "drape/game/scene_description.hpp"
#include "drape/systems/cloth/garment_builder.hpp"

namespace drape {

/// Upper bound on particles per garment accepted from a scene: the garment builders' own.
inline constexpr int max_scene_particles = max_garment_particles;

/// Reads and checks a scene file. Relative paths resolve against its folder; character
/// files must exist.
[[nodiscard]] Result<SceneDescription> load_scene_file(const std::filesystem::path& file);

/// Parses scene JSON text. `label` names the source in errors; `base_dir` resolves
/// relative paths.
[[nodiscard]] Result<SceneDescription> parse_scene(std::string_view text, std::string_view label,
                                                   const std::filesystem::path& base_dir);

/// Checks a description built in code (the same rules as the file, without positions).
[[nodiscard]] Result<void> validate(const SceneDescription& scene);

/// Scene JSON for a description (paths written as given); parse_scene reads it back equal.
[[nodiscard]] std::string to_json(const SceneDescription& scene);

/// 1-based line and column of a byte offset in text.
[[nodiscard]] std::pair<int, int> line_column(std::string_view text, std::size_t offset);

}  // namespace drape
