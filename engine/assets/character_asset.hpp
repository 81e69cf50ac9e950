// What importing a character produces: immutable data shared by every instance.
//
// Conventions after import (method §1, §2): metres, Y up, model space = the file's scene
// root after the unit and axis correction; every vertex has at most 4 bone influences
// whose weights sum to 1; clip times in seconds. What Drape derives from a character for
// its garments (fitted ellipsoids, the hip bone) is systems/character/character_body.hpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "drape/engine/assets/animation_clip.hpp"
#include "drape/engine/assets/mesh_asset.hpp"
#include "drape/engine/assets/skeleton_asset.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// How the importer chose the file's unit scale.
enum class ScaleSource : std::uint8_t {
    option,     ///< ImportOptions::scale.
    height,     ///< ImportOptions::height_m.
    file_units, ///< The file's unit metadata (FBX UnitScaleFactor, COLLADA <unit>, glTF = metres).
    fallback,   ///< The file states no unit, or its unit gives an implausible height: scaled to ImportOptions::fallback_height_m.
};
[[nodiscard]] const char* scale_source_name(ScaleSource source) noexcept;

/// One mesh of the file as it ended up in the merged MeshAsset.
struct MeshInfo {
    std::string name;
    std::uint32_t first_vertex = 0;
    std::uint32_t vertex_count = 0;
    bool rigid = false;   ///< Had no skin: bound with weight 1 to the bone it hangs from.
    std::string material; ///< Its material's name ("" when it has none).
    bool has_uvs = false; ///< Has a UV set (MeshAsset::uvs).
};

struct CharacterAsset {
    std::filesystem::path source;
    std::string name;                                   ///< File stem.
    std::shared_ptr<const SkeletonAsset> skeleton;
    std::shared_ptr<const MeshAsset> mesh;               ///< All meshes of the file, merged.
    std::vector<std::shared_ptr<const AnimationClip>> clips;
    std::vector<MeshInfo> meshes;
    Real height_m = 0;                                  ///< Vertical extent of the rest pose.
    double scale = 1;                                   ///< File units -> metres that was applied.
    ScaleSource scale_source = ScaleSource::file_units;
    /// What the file states of its units and up axis ("FBX UnitScaleFactor 1 (1 unit =
    /// 1 cm), UpAxis Y"), and with ScaleSource::fallback why its units were not used; one line.
    std::string units_note;
    int skin_bones = 0;                                 ///< Bones that move at least one vertex.
    /// What the import accepted but a user may want to know (e.g. zero-length end bones
    /// without weights): one line each, naming the file.
    std::vector<std::string> warnings;
};

}  // namespace drape
