// Cloth constraint system (method §4): Provot's strain limit on the warp (§4.1); in the
// simplified model the weft (layer 2) placed from layer 1 (§4.2); in the classic model
// Provot on warp and weft. Second of the three cloth systems in every substep, timed as
// "cloth_constraint".
#pragma once

#include "systems/cloth/garment_batch.hpp"
#include "systems/cloth/garment_step.hpp"

namespace drape {

/// One substep of every garment of `batch`, in parallel over garments. After the last
/// substep's constraints it records each garment's largest strain.
void run_cloth_constraint(const GarmentBatch& batch, const ClothSubstep& substep);

}  // namespace drape
