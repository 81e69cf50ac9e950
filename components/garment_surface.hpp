// GarmentSurface component: the surface a garment from an artist's mesh is drawn as
// (docs/garments.md "Drawn as authored"). The simulation runs on the particle grid cut from
// the mesh's pattern (systems/cloth/garment_from_mesh.hpp); what is drawn is the artist's own
// mesh, each of its vertices carried by the grid triangle it lay on when the garment was cut:
// its barycentric weights on that triangle's three particles and its distance along the
// normal there (the particles' vertex normals, weighted the same way: smooth across the
// grid's triangles, as the grid itself is shaded), with its UVs and base-colour texture.
// Plain data: the garment surface system places `positions` and `normals` from the
// particles once per drawn frame and the render system draws them instead of the grid.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "drape/engine/core/image.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

struct GarmentSurface {
    std::vector<std::uint32_t> triangles;                ///< The artist's triangles, three indices each.
    std::vector<std::array<std::uint32_t, 3>> carriers;  ///< Per vertex: the three particles carrying it.
    Matrix3X weights;                                    ///< Per vertex: their barycentric weights (sum 1).
    VectorX offset_m;                                    ///< Per vertex: along the carriers' normal, (b - a) x (c - a).
    Matrix3X positions;                                  ///< World, m: written once per drawn frame.
    Matrix3X normals;                                    ///< World, unit: the particles' normals, carried the same way.
    Matrix3X particle_normals;                           ///< Scratch: the grid's vertex normals this frame.
    Matrix2X uvs;                                        ///< Per vertex: the artist's UVs; empty: none.
    std::shared_ptr<const Image> base_color;             ///< The artist's base-colour texture (sRGB, by `uvs`); null: none.
};

}  // namespace drape
