// Cloth collision system (method §5): every garment against the ellipsoids of its body at
// the end of the substep, with candidate lists and temporal coherence, then the
// non-finite check. Last of the three cloth systems in every substep, timed as
// "cloth_collision".
#pragma once

#include "engine/core/registry.hpp"
#include "systems/cloth/garment_batch.hpp"
#include "systems/cloth/garment_step.hpp"

namespace drape {

/// One substep of every garment of `batch`, in parallel over garments.
void run_cloth_collision(const Registry& registry, const GarmentBatch& batch, const ClothSubstep& substep);

}  // namespace drape
