// A character's bones: shared hierarchy and bind pose, per-instance pose (method §1.1).
#pragma once

#include <memory>
#include <vector>

#include "drape/engine/assets/skeleton_asset.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// Per-instance pose. Written by the animation system.
struct Skeleton {
    std::shared_ptr<const SkeletonAsset> asset;
    std::vector<Affine3> local;      ///< Current bone -> parent.
    std::vector<Affine3> global;     ///< Current bone -> model space.
    std::vector<Affine3> skinning;   ///< global * inverse_bind: bind model space -> current model space.
};

}  // namespace drape
