// Changing a garment while it runs. The model and the material decide the solver's stability
// bounds and the reach of its candidate lists, and the particles' places its temporal
// coherence (systems/cloth/garment_solver.hpp); these functions change them and drop what
// depended on the old values.
#pragma once

#include "drape/components/garment.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/engine/core/registry.hpp"

namespace drape {

/// Switches the garment's mass-spring model (method §3.1). False when `garment` has no Garment.
bool set_garment_model(Registry& registry, Entity garment, ClothModel model);

/// Replaces the garment's material after checking it (the error names the field, e.g.
/// "material.stretch_N_m"); on an error nothing changes.
[[nodiscard]] Result<void> set_garment_material(Registry& registry, Entity garment, const ClothMaterial& material);

/// Puts the particles at `x` with velocities `v` (a saved state, a checkpoint); pins keep
/// their bindings. The error says what does not fit; on an error nothing changes.
[[nodiscard]] Result<void> set_garment_state(Registry& registry, Entity garment, const Matrix3X& x, const Matrix3X& v);

}  // namespace drape
