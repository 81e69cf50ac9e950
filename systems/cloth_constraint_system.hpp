// Cloth constraint system (method §4): Gauss-Seidel rounds of tethers, springs in
// compliance form and Provot's strain limit (§4.1), alternating with the collision system's
// rounds; then the substep's velocities and, in the simplified model, the weft (layer 2)
// placed from layer 1 (§4.2). Timed as "cloth_constraint".
#pragma once

#include "systems/cloth/garment_batch.hpp"
#include "systems/cloth/garment_step.hpp"

namespace drape {

/// Round `round` of every garment of `batch` that takes that many rounds, in parallel.
void run_cloth_constraint_round(const GarmentBatch& batch, const ClothSubstep& substep, int round);

/// After the rounds: velocities and the weft of every garment, in parallel.
void run_cloth_constraint_finish(const GarmentBatch& batch, const ClothSubstep& substep);

}  // namespace drape
