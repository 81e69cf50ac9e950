// Layer-2 (weft) placement (method §3.2, §4.2).
//
// Step order, after the warp constraints have fixed layer 1 (method §4.2):
//   1. Normals of the layer-1 particles from the grid stencil (warp tangent x weft tangent).
//   2. For each layer-2 particle between layer-1 neighbours a and b (fraction t):
//      the plane through x_a spanned by the edge e = x_b - x_a and the average normal
//      n = n_a + n_b has unit normal p = e x n / |e x n|;
//      velocity: v = (1 - t) v_a + t v_b, projected onto the plane (v -= (v.p) p);
//      position: x += h v, then projected onto the plane.
//   3. Provot on the weft springs and on the warp springs of layer-2 lines with layer 1
//      held still, moving layer-2 particles only within their planes (strain_limit.hpp).
#pragma once

#include "components/garment.hpp"
#include "engine/core/math.hpp"

namespace drape {

/// Step 1: unit normals of the layer-1 particles (columns [0, layer1_count) of `normals`).
void compute_layer1_normals(const GarmentTopology& topology, const Matrix3X& x, Matrix3X& normals);

/// Step 2: places the free layer-2 particles and writes each one's plane normal into
/// `plane_normal` (zero for particles without a plane).
void place_weft(const GarmentTopology& topology, const Matrix3X& normals, const VectorX& inv_mass, Matrix3X& x,
                Matrix3X& v, Matrix3X& plane_normal, Real h_s);

/// Signed distance of layer-2 particle `k` (index into topology.weft_particle) from its
/// plane at the current positions, m (for tests and diagnostics).
[[nodiscard]] Real weft_plane_distance(const GarmentTopology& topology, const Matrix3X& normals,
                                       const Matrix3X& x, std::size_t k);

}  // namespace drape
