// A character's skin: shared bind-pose mesh and weights, per-instance skinned vertices.
#pragma once

#include <memory>

#include "engine/assets/mesh_asset.hpp"
#include "engine/core/math.hpp"

namespace drape {

/// Per-instance skinned vertices in world space. Written by the skinning system.
struct SkinnedMesh {
    std::shared_ptr<const MeshAsset> mesh;
    Matrix3X positions;   ///< World space, metres.
    Matrix3X normals;     ///< World space, unit.
};

}  // namespace drape
