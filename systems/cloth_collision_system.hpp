// Cloth collision system (method §5): every garment against the ellipsoids of its body,
// with candidate lists and temporal coherence. In each of the constraint system's rounds
// every free particle (both layers) is moved out, positions only, and its push recorded for
// the velocities; after the rounds, the non-finite check. Timed as "cloth_collision".
#pragma once

#include "drape/engine/core/registry.hpp"
#include "drape/systems/cloth/garment_batch.hpp"
#include "drape/systems/cloth/garment_step.hpp"

namespace drape {

/// Colliders and candidate lists of every garment for the substep, in parallel.
void run_cloth_collision_prepare(const Registry& registry, const GarmentBatch& batch, const ClothSubstep& substep);

/// Round `round` of every garment of `batch` that takes that many rounds, in parallel.
void run_cloth_collision_round(const Registry& registry, const GarmentBatch& batch, const ClothSubstep& substep, int round);

/// After the rounds, every garment, in parallel.
void run_cloth_collision_finish(const Registry& registry, const GarmentBatch& batch, const ClothSubstep& substep);

}  // namespace drape
