// Layer-2 (weft) placement (method §3.2, §4.2).
//
// Step order, after the warp constraints have fixed layer 1 (method §4.2):
//   1. Normals of the layer-1 particles from the grid stencil (warp tangent x weft tangent).
//   2. For each layer-2 particle between layer-1 neighbours a and b (fraction t):
//      the plane through x_a spanned by the edge e = x_b - x_a and the average normal
//      n = n_a + n_b has unit normal p = e x n / |e x n|;
//      velocity: v = (1 - t) v_a + t v_b, projected onto the plane (v -= (v.p) p);
//      position: the particle has no mass and no state of its own along the weft: it sits
//      at q = (1 - t) x_a + t x_b on the edge plus a bulge b along u = p x e/|e|, the
//      in-plane direction across the edge. The bulge is what it had after the last
//      substep (the collision pushes it out of the body), carried by the velocity:
//      b = (x + h v - q) . u.
//   3. Provot on layer 2 (§4.2 item 3), on the one free coordinate b, from the pins outward:
//      - weft: W = [-beta/2, beta/2], beta = sqrt(l^2 - (|e| / stride)^2), l = (1 + limit)
//        x the mean rest of the weft segments between a and b. With every bulge of a row in
//        W, each weft segment is at most l (its along-edge part is |e| / stride); when the
//        chord itself is longer than stride x l, W = {0} and the segments are |e| / stride.
//      - warp: I = the bulges that keep the spring to the particle above (placed first)
//        within (1 + limit) x rest. b = the carried bulge clamped to I and W.
//      - When I and W do not meet, the particles above on the same line go back onto their
//        chords (b = 0), upward until the spring above the topmost one holds. On chords a
//        layer-2 warp spring is the blend (1 - t) d_a + t d_b of the two layer-1 warp
//        springs beside it, so its length is at most the same blend of theirs: within
//        (1 + limit) x rest when theirs are (Provot's ordered pass, §4.1) and its rest is
//        that blend of their rests (grid builders: equal). 0 is then in I and in W.
//   Guarantees after the placement: every layer-2 warp spring with a free end is at most
//   (1 + limit) x rest (below the pins once the chords are within reach, see
//   lift_chords_below_pins); every weft segment beside a free layer-2 particle that does
//   not hang from a pinned one is at most max(l, |e| / stride). A particle hanging from a
//   pinned one gets its warp spring first (I alone if it misses W, else the nearest bulge):
//   the fitting zone's skin points curve around the body, off the planes below them.
//   Layer-2 particles are listed line by line from the pins outward, so the particle
//   above is always placed first.
#pragma once

#include "components/garment.hpp"
#include "engine/core/math.hpp"

namespace drape {

/// Step 1: unit normals of the layer-1 particles (columns [0, layer1_count) of `normals`).
void compute_layer1_normals(const Fabric& topology, const Matrix3X& x, Matrix3X& normals);

/// Before step 2, under the fitting zone (method §3.5): where a layer-2 particle hangs from a
/// pinned one whose skin point lies farther than (1 + limit) x rest from the particle's chord
/// point, the chord's free layer-1 ends move toward the pinned particle, while every layer-1
/// warp spring from a pinned particle to a free one stays within (1 + limit) x rest:
/// alternating projections onto both sets of constraints, aimed 0.5 % inside the limits, until
/// every chord point is within reach (at most 32 rounds; velocities follow when h_s > 0). The
/// chord is then a place the particle may take, so the back-off of step 3 holds its warp
/// spring too. `scratch`: 3 x layer1_count or more. True when anything moved: the layer-1 warp
/// then needs its ordered Provot pass again (it leaves the springs from the pins as they are).
bool lift_chords_below_pins(const Fabric& topology, const VectorX& inv_mass, Matrix3X& x, Matrix3X& v,
                            Matrix3X& scratch, Real h_s, Real strain_limit = Real(0.10));

/// Steps 2-3: places the free layer-2 particles and writes each one's plane normal into
/// `plane_normal` (zero for particles without a plane).
void place_weft(const Fabric& topology, const Matrix3X& normals, const VectorX& inv_mass, Matrix3X& x,
                Matrix3X& v, Matrix3X& plane_normal, Real h_s, Real strain_limit = Real(0.10));

/// Signed distance of layer-2 particle `k` (index into topology.weft_particle) from its
/// plane at the current positions, m (for tests and diagnostics).
[[nodiscard]] Real weft_plane_distance(const Fabric& topology, const Matrix3X& normals,
                                       const Matrix3X& x, std::size_t k);

}  // namespace drape
