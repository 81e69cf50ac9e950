// Layer-2 (weft) particles (method §3.2, §4.2).
//
// A layer-2 particle between layer-1 neighbours a and b lives in the plane through x_a
// spanned by the edge e = x_b - x_a and the average normal n = n_a + n_b (unit normal
// p = e x n / |e x n|, item 1). The paper confines it to that plane without saying where in
// it; Drape keeps its place there as two coordinates relative to its chord point
// q = (1 - t) x_a + t x_b (t: its share of the chord's rest length): along e, and along
// u = p x e / |e|, across the chord toward the cloth's outer side.
// Step order in a substep:
//   1. Normals of the layer-1 particles from the grid stencil (warp tangent x weft tangent).
//   2. place_weft, once layer 1 is predicted: each free layer-2 particle at its coordinates
//      in its chord's new frame, so it moves as its neighbours moved (its velocity is
//      theirs, projected onto its plane: item 2);
//   3. the constraint rounds hold its springs (item 3: Provot on layer 2) and keep it out
//      of the body;
//   4. record_weft_offsets: its coordinates in its plane where the rounds left it (what
//      they moved it off its plane is dropped: item 1).
// Layer-2 particles carry no mass of their own in the integration; their mass goes to their
// layer-1 neighbours (garment_solver.hpp).
#pragma once

#include "components/garment.hpp"
#include "engine/core/math.hpp"

namespace drape {

/// Step 1: unit normals of the layer-1 particles (columns [0, layer1_count) of `normals`).
void compute_layer1_normals(const Fabric& fabric, const Matrix3X& x, Matrix3X& normals);

/// Step 2: every free layer-2 particle at `offsets` (2 x entries of fabric.weft_particle)
/// in its chord's frame; writes each plane's unit normal into `plane_normal` (zero for
/// particles without a plane). A degenerate chord leaves its particle where it is.
void place_weft(const Fabric& fabric, const Matrix3X& normals, const VectorX& inv_mass, const Matrix2X& offsets,
                Matrix3X& x, Matrix3X& plane_normal);

/// Step 4: the coordinates of every layer-2 entry in its chord's frame at positions `x`.
void record_weft_offsets(const Fabric& fabric, const Matrix3X& normals, const Matrix3X& x, Matrix2X& offsets);

/// Signed distance of layer-2 particle `k` (index into fabric.weft_particle) from its
/// plane at the current positions, m (for tests and diagnostics).
[[nodiscard]] Real weft_plane_distance(const Fabric& fabric, const Matrix3X& normals, const Matrix3X& x, std::size_t k);

}  // namespace drape
