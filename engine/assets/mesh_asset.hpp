// A character's skin as imported: bind-pose mesh, bone weights and submeshes (method §1.2).
// Shared, immutable data; the per-instance skinned vertices are components/skinned_mesh.hpp.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "drape/engine/core/math.hpp"

namespace drape {

/// A range of triangles with its own material colour (one per imported mesh).
struct Submesh {
    std::string name;
    std::uint32_t first_index = 0;   ///< Into MeshAsset::indices.
    std::uint32_t index_count = 0;
    Vec3 color = Vec3(0.8f, 0.7f, 0.6f);  ///< Linear RGB.
};

/// Immutable mesh data shared by every instance (method §1.2).
struct MeshAsset {
    Matrix3X bind_positions;                  ///< Model space at bind, metres.
    Matrix3X bind_normals;
    Eigen::Matrix<std::int32_t, 4, Eigen::Dynamic> bone_indices;  ///< Up to 4 influences (unused: index 0, weight 0).
    Matrix4X bone_weights;                    ///< Each column sums to 1.
    Matrix2X uvs;                             ///< First UV set per vertex (0, 0 in a mesh without one: MeshInfo::has_uvs).
    std::vector<std::uint32_t> indices;       ///< Triangles, counter-clockwise.
    std::vector<Submesh> submeshes;

    [[nodiscard]] std::size_t vertex_count() const noexcept { return static_cast<std::size_t>(bind_positions.cols()); }
};

}  // namespace drape
