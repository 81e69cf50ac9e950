// Character import through assimp: glTF 2.0 (.glb/.gltf), FBX, COLLADA, and BVH motion.
//
// Normalisation (method §1, §2): metres (ImportOptions::scale, else ImportOptions::height_m,
// else the file's unit metadata, falling back to a standard height when the file's units
// give an implausible one), Y up (FBX axis metadata; COLLADA's up axis is applied by assimp),
// at most 4 weights per vertex summing to 1, clip times in seconds (assimp reports glTF
// times in milliseconds through mTicksPerSecond), all meshes merged into one MeshAsset with
// one submesh each. Meshes parented rigidly to a bone become skinned vertices with weight
// 1 on it. Skinning uses the file's inverse bind matrices, which may differ from its node
// pose (the bind pose is kept, the node pose is the rest pose).
//
// Every failure is one line naming the file and the reason.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "drape/engine/assets/character_asset.hpp"
#include "drape/engine/core/error.hpp"

namespace drape {

struct ImportOptions {
    std::optional<double> scale;        ///< File units -> metres; overrides everything else.
    std::optional<double> height_m;     ///< Scale the rest pose to this height.
    double fallback_height_m = 1.75;    ///< Used when the file's units give a height outside the plausible range.
    double min_plausible_height_m = 0.3;
    double max_plausible_height_m = 2.6;
    bool require_animation = true;      ///< A file without clips is an error (set false to add BVH clips later).
};

/// Checks the options; the error names the field.
[[nodiscard]] Result<void> validate(const ImportOptions& options);

/// The rotation from a file's axes to Drape's (X right, Y up, Z front), given which file
/// axis (0 = X, 1 = Y, 2 = Z) and sign is up, front and right (FBX's UpAxis, FrontAxis,
/// CoordAxis metadata). Identity when the axes are not a permutation.
[[nodiscard]] Mat3 axes_to_drape(int up, int up_sign, int front, int front_sign, int coord, int coord_sign);

/// Imports a character file.
[[nodiscard]] Result<std::shared_ptr<const CharacterAsset>> import_character(const std::filesystem::path& path,
                                                                             const ImportOptions& options = {});

/// Imports the motion of a BVH file onto a skeleton whose bone names match the BVH joints
/// (every joint must exist with the same parent). Root translation is rescaled from the
/// BVH's units by comparing bone lengths.
[[nodiscard]] Result<std::shared_ptr<const AnimationClip>> import_bvh_motion(const std::filesystem::path& path,
                                                                             const SkeletonAsset& skeleton);

/// A clip by exact name, else by the part after the last '|' when unique ("Man_Walk" for
/// "HumanArmature|Man_Walk"), else by index ("0", "3"). The error lists the clips there are.
[[nodiscard]] Result<std::size_t> find_clip(const CharacterAsset& character, std::string_view name_or_index);

/// The clip played when none is named, and why (for logs and `drape inspect`).
struct ClipChoice {
    std::size_t index = 0;
    std::string reason;  ///< e.g. "Walking (name says walk)".
};

/// Picks the clip to play when none is named: a clip whose name says walk; else a looping
/// locomotion clip (name says run, jog, step, stride, march or locomotion); else an idle
/// (name says idle or breath); else clip 0. A name is read as words ("Man_Walk",
/// "WalkJump" and "walk-cycle" all say walk); among several walks, one whose name names no
/// other action (jump, turn, back, ...) wins, then one that loops, then the first. A clip
/// loops when every channel's last rotation key matches its first. nullopt: no clips.
[[nodiscard]] std::optional<ClipChoice> choose_default_clip(const CharacterAsset& character);

/// The clip's motion bone and travel (AnimationClip::motion_bone, travel_m, travel_local)
/// from its keys and the skeleton's rest pose.
void compute_clip_travel(AnimationClip& clip, const SkeletonAsset& skeleton);

}  // namespace drape
