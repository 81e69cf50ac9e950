// A garment's simulated surface as a triangle mesh, for a game that draws it with its own
// renderer instead of Drape's render system: world-space positions (one vertex per
// particle), the same area-weighted normals the render system shades with, the triangles
// over the particle grid and the garment's colour.
#pragma once

#include <cstdint>
#include <vector>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/math.hpp"
#include "drape/engine/core/registry.hpp"

namespace drape {

struct GarmentMesh {
    Matrix3X positions;                    ///< World, m; one column per particle.
    Matrix3X normals;                      ///< World, unit; one per position.
    std::vector<std::uint32_t> triangles;  ///< Counter-clockwise = outside; indices into positions.
    Vec3 color = Vec3::Ones();             ///< Linear RGB.
};

/// Reads the garment entity's mesh after a step into `out`, reusing its buffers (no
/// allocation once sized). Errors name what is missing: no such entity, no Garment on it,
/// a garment not built.
[[nodiscard]] Result<void> read_garment_mesh(const Registry& registry, Entity garment, GarmentMesh& out);

}  // namespace drape
