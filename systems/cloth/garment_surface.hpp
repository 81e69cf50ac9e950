// The artist's mesh carried by a garment's particles (components/garment_surface.hpp;
// docs/garments.md "Drawn as authored").
//
// Embedding, once, where the garment is cut: each vertex of the mesh goes to the nearest
// point of the grid's triangles (Fabric::triangles on the cut grid, through the skin
// surface's closest-point queries, systems/character/skin_surface.hpp), as the barycentric
// weights of that triangle's three particles and the vertex's signed distance from it along
// the normal there: the particles' vertex normals weighted the same way, so that the surface and its shading are as smooth across the grid's
// triangles as the grid's own. Placing, once per drawn frame: the same weights on where the
// particles are now, the same distance along that normal now, which is also the vertex's
// normal. A vertex on the grid's surface is carried exactly; one off it (a fold the grid's
// spacing cannot hold, a border past the grid's last row) keeps only its distance along
// the normal.
#pragma once

#include <cstdint>
#include <span>

#include "drape/components/garment.hpp"
#include "drape/components/garment_surface.hpp"
#include "drape/engine/assets/garment_file.hpp"
#include "drape/systems/cloth/garment_builder.hpp"

namespace drape {

/// `mesh` embedded in `grid` (both in the same space, the character's model space), the
/// carriers named by `fabric`'s particles (Fabric::grid maps the grid's order to them).
[[nodiscard]] GarmentSurface embed_surface(const GarmentMeshAsset& mesh, const GridGarment& grid, const Fabric& fabric);

/// Places `surface.positions` and `surface.normals` on the particles `x` of a garment whose
/// triangles (Fabric::triangles) are `triangles`.
void place_surface(GarmentSurface& surface, const Matrix3X& x, std::span<const std::uint32_t> triangles);

}  // namespace drape
