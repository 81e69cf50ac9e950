// A character's clip written as a BVH motion: how Drape hands a motion to other tools, and
// how its tests make motions in other rigs' naming (tests/character/bvh_retarget_test.cpp).
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>

#include "drape/engine/assets/animation_clip.hpp"
#include "drape/engine/assets/skeleton_asset.hpp"
#include "drape/engine/core/error.hpp"

namespace drape {

/// Writes `clip` played on `skeleton` (not in place) as a BVH file, in the convention
/// import_bvh_motion reads: every bone a joint, named `rename(bone name)` (the bone's own
/// name when `rename` is empty); offsets the bones' rest offsets in model space, metres;
/// each joint's rotation its world turn from rest relative to its parent's, channels Z X Y;
/// the root's position its model-space place; `frames_per_s` samples from 0 to the clip's
/// end. The skeleton must have one root. Never overwrites: an existing file is an error.
[[nodiscard]] Result<void> write_bvh_motion(const std::filesystem::path& path, const AnimationClip& clip,
                                            const SkeletonAsset& skeleton, double frames_per_s = 30,
                                            const std::function<std::string(std::string_view)>& rename = {});

}  // namespace drape
