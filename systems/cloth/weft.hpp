// Layer-2 (weft) particles of the simplified model (method §3.2, §4.2).
//
// A layer-2 particle has no force of its own: each substep it is carried by the two
// layer-1 neighbours of its row, a and b, by its share t of the chord between them (the
// rest length of the weft segments before it over that of the whole chord):
//   x_p += (1 - t) (x_a - x_a,start) + t (x_b - x_b,start)
// once layer 1 is predicted, so its velocity is its neighbours' velocities blended by its
// place on the chord (item 2). The constraint rounds then hold its springs (item 3:
// Provot on layer 2) and keep it out of the body, with its own mass.
//
// Item 1 (the particle moves only in the plane of the chord and the neighbours' average
// normal) is not enforced: projecting the carried particle onto that plane every substep
// raised the skirt's after-frame strain on the walk from p99 6.4 %, max 10.4 % to 9.9 %,
// 24 % (docs/cloth.md, "Choices the paper leaves open").
#pragma once

#include <cstdint>
#include <span>

#include "drape/components/garment.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// Carries free layer-2 particles of `fabric` with its neighbours: `x_start` are the
/// positions at the start of the substep, `x` holds layer 1 predicted and layer 2 as it was;
/// on return layer 2 has moved as above. Pinned particles (`inv_mass` 0) are left alone.
/// `entries`: the Fabric::weft_particle entries to carry.
void carry_weft(const Fabric& fabric, std::span<const std::uint32_t> entries, const VectorX& inv_mass,
                const Matrix3X& x_start, Matrix3X& x);

}  // namespace drape
