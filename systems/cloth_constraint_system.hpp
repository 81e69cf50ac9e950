// Cloth constraint system (method §4): Gauss-Seidel rounds of springs in compliance form
// with Provot's strain limit (§4.1), then tethers, alternating with the collision system's
// rounds; in the simplified model the first round places the weft (layer 2) from layer 1
// (§4.2). After the rounds: the substep's velocities from its moves and, in the simplified
// model, the weft's places recorded for the next substep. Timed as "cloth_constraint".
#pragma once

#include "drape/systems/cloth/garment_batch.hpp"
#include "drape/systems/cloth/garment_step.hpp"

namespace drape {

/// Round `round` of every garment of `batch` that takes that many rounds, in parallel.
void run_cloth_constraint_round(const GarmentBatch& batch, const ClothSubstep& substep, int round);

/// After the rounds: velocities and the weft of every garment, in parallel.
void run_cloth_constraint_finish(const GarmentBatch& batch, const ClothSubstep& substep);

}  // namespace drape
