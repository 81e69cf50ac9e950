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
#include <utility>
#include <vector>

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

/// Which humanoid part a bone's name names, as motion retargeting reads it: "hips",
/// "spine", "neck", "head", or a limb part with its side ("upper_leg.l", "lower_leg.r",
/// "foot.l", "toe.l", "shoulder.l", "upper_arm.l", "lower_arm.l", "hand.l"); empty for
/// anything else (fingers, twist and helper bones, connectors). Reads the common schemes:
/// Mixamo ("mixamorig:LeftUpLeg", "LeftForeArm"), CMU BVH ("LeftUpLeg", "LHipJoint" is a
/// connector), Blender and Quaternius ("UpperLeg.L", "thigh_l", "UpperLegL"), glTF samples.
[[nodiscard]] std::string humanoid_part(std::string_view bone_name);

/// How a motion's joints are matched to a character's bones.
struct MotionRetarget {
    /// Joint name -> bone name, before the built-in matching (a scene's "motion_bones").
    std::vector<std::pair<std::string, std::string>> bones;
};

/// Imports the motion of a BVH file onto a skeleton, retargeted (docs/characters.md,
/// "Motion from a BVH file"): each joint drives the bone of the same name, else the bone
/// `retarget` names, else the bone of the same humanoid part (humanoid_part); the spine
/// chain between the hips and the neck is matched by its share of the chain. Each driven
/// bone turns in the world as its joint turns from the motion's rest pose, after the
/// rotation that takes the bone's rest direction (toward the next driven bone) onto its
/// joint's (the hips: their up and left-right axes), so that a T-posed motion drives an
/// A-posed character. The root's path is scaled by the ratio of the legs' lengths. Without
/// hips and both legs matched: an error naming what is missing. `notes` (when given) gets
/// one line naming the joints that drive nothing and the character's limb bones no joint
/// drives, when there are any.
[[nodiscard]] Result<std::shared_ptr<const AnimationClip>> import_bvh_motion(const std::filesystem::path& path,
                                                                             const SkeletonAsset& skeleton,
                                                                             const MotionRetarget& retarget = {},
                                                                             std::vector<std::string>* notes = nullptr);

/// A clip by exact name, else by the part after the last '|' when unique ("Man_Walk" for
/// "HumanArmature|Man_Walk"), else by index ("0", "3"). The error lists the clips there are.
[[nodiscard]] Result<std::size_t> find_clip(const CharacterAsset& character, std::string_view name_or_index);

/// The clip played when none is named, and why (for logs and `drape inspect`).
struct ClipChoice {
    std::size_t index = 0;
    std::string reason;  ///< e.g. "Walking (name says walk)".
    bool fell_back = false;  ///< No walk and no looping locomotion clip: an idle or the first clip.
};

/// How far a clip is from a loop: the largest angle between a channel's first and last
/// rotation key, radians (0 for a clip without rotation keys).
[[nodiscard]] Real loop_mismatch_rad(const AnimationClip& clip) noexcept;

/// A clip whose first and last poses are at most this far apart loops. Exports of a cycle
/// often end a little off their first pose (a looping run whose ends differ by 6.3
/// degrees); 15 degrees covers those, while a clip that goes somewhere (a turn, a fall)
/// ends much farther off.
inline constexpr Real near_loop_tolerance_rad = Real(15 * 3.14159265358979323846 / 180);

/// Whether the clip loops: it has channels and loop_mismatch_rad() <= near_loop_tolerance_rad.
[[nodiscard]] bool clip_loops(const AnimationClip& clip) noexcept;

/// Marks a near-loop (clip_loops(), ends not on each other) for a blended seam: sets
/// AnimationClip::seam_blend_s to a fifth of the clip, at most 0.2 s. The importer does
/// this for every clip.
void blend_loop_seam(AnimationClip& clip) noexcept;

/// Picks the clip to play when none is named: a clip whose name says walk; else a looping
/// locomotion clip (name says run, jog, step, stride, march or locomotion); else an idle
/// (name says idle or breath); else clip 0. A name is read as words ("Man_Walk",
/// "WalkJump" and "walk-cycle" all say walk); among several walks, one whose name names no
/// other action (jump, turn, back, ...) wins, then one that loops, then the first. A clip
/// loops when clip_loops() says so (its ends within 15 degrees). nullopt: no clips.
[[nodiscard]] std::optional<ClipChoice> choose_default_clip(const CharacterAsset& character);

/// The clip's motion bone and travel (AnimationClip::motion_bone, travel_m, travel_local)
/// from its keys and the skeleton's rest pose.
void compute_clip_travel(AnimationClip& clip, const SkeletonAsset& skeleton);

}  // namespace drape
