// Area-weighted vertex normals of a triangle mesh: the renderer shades the cloth with them,
// and a game reading a garment's mesh for its own renderer gets the same ones.
#pragma once

#include <cstdint>
#include <span>

#include "drape/engine/core/math.hpp"

namespace drape {

/// Per vertex of `x`: the normalised sum of its triangles' area-weighted normals
/// (counter-clockwise = front); +Y for a vertex without a triangle of non-zero area.
void vertex_normals(const Matrix3X& x, std::span<const std::uint32_t> triangles, Matrix3X& normals);

}  // namespace drape
