// A character's skin: shared bind-pose mesh and weights, per-instance skinned vertices.
//
// The skinned vertices are for drawing only: the cloth follows the skeleton (colliders on
// bones, pins skinned from Skeleton::skinning), so the skinning system runs in the render
// phase and only in a world that renders. A headless world leaves `positions` as spawning
// left them.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "drape/engine/assets/mesh_asset.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// Per-instance skinned vertices in world space. Written at spawn and by the skinning system.
struct SkinnedMesh {
    std::shared_ptr<const MeshAsset> mesh;
    Matrix3X positions;   ///< World space, metres.
    Matrix3X normals;     ///< World space, unit.
    std::uint64_t skinned_vertices = 0;  ///< Vertices skinned into `positions` since spawn (a count, not a time).
    std::vector<char> hidden;            ///< Per submesh, nonzero: not drawn (a modelled garment under a simulated one). Empty: all drawn.
};

}  // namespace drape
