// Skeletal animation and skinning as free functions on Eigen data (method §1.1, §1.2).
//
// A frame: wrap the clip time, sample every channel into local bone transforms (lerp for
// translation and scale, slerp for rotation), compose them down the hierarchy (parents
// come before children), form the skinning matrices global * inverse_bind, and blend
// them per vertex (linear blend skinning). The systems in systems/*_system.cpp only
// call these. Composing, skinning matrices and blending are plain transform math the
// importer needs too (the rest pose's height); they live in engine/assets/skinning.hpp,
// which this header includes.
#pragma once

#include <span>
#include <vector>

#include "drape/engine/assets/animation_clip.hpp"
#include "drape/engine/assets/skeleton_asset.hpp"
#include "drape/engine/assets/skinning.hpp"  // compose_pose, skinning_matrices, skin_mesh: the rest of a frame
#include "drape/engine/core/math.hpp"

namespace drape {

/// Where a playback time falls in a clip.
struct ClipTime {
    double time_s = 0;   ///< In [0, duration].
    int cycles = 0;      ///< Whole loops before it (0 when not looping).
};

/// Wraps `time_s` into the clip: modulo the duration when looping, clamped otherwise.
[[nodiscard]] ClipTime wrap_clip_time(double time_s, double duration_s, bool loop) noexcept;

/// TRS -> affine (translation * rotation * scale).
[[nodiscard]] Affine3 compose_trs(const Vec3& translation, const Quat& rotation, const Vec3& scale) noexcept;

/// Local pose at `time_s` (seconds within the clip). Bones the clip does not animate keep
/// their rest pose; channels for out-of-range bones are ignored. `in_place` removes the
/// clip's horizontal travel from its motion bone. `loop`: the clip is played as a loop, and a
/// near-loop's seam is blended (AnimationClip::seam_blend_s): over its last stretch each
/// channel turns (and moves) by a growing share of the gap from its last key to its first,
/// eased in and out, so the pose at the end is the pose at the start. `local` is resized
/// to the skeleton.
void sample_clip(const AnimationClip& clip, const SkeletonAsset& skeleton, double time_s, bool in_place,
                 std::vector<Affine3>& local, bool loop = false);

/// The rest (node) pose.
void rest_pose(const SkeletonAsset& skeleton, std::vector<Affine3>& local);

}  // namespace drape
