// Cloth integration system (method §3.3-§3.5): the explicit prediction of paper eq. 2's
// body-driven, gravity and drag forces in the anchor's frame on the integrated particles
// (simplified model: layer 1; classic: all; the springs act in the constraint rounds),
// then the fitting-zone pins. First of the three cloth systems
// in every substep; the cloth
// step (cloth_systems.hpp) runs it and times it as "cloth_integration".
#pragma once

#include "drape/engine/core/registry.hpp"
#include "drape/systems/cloth/garment_batch.hpp"
#include "drape/systems/cloth/garment_step.hpp"

namespace drape {

/// One substep of every garment of `batch`, in parallel over garments. At the first
/// substep it also starts each garment's step (counters, pin targets).
void run_cloth_integration(const Registry& registry, const GarmentBatch& batch, const ClothSubstep& substep);

}  // namespace drape
