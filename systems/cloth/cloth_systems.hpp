// The three cloth systems in their order, with the substep rule (method §3.4).
#pragma once

#include "engine/core/scheduler.hpp"
#include "systems/cloth/substeps.hpp"

namespace drape {

/// Adds cloth_integration, cloth_constraint and cloth_collision (phase simulation, in that
/// order) and installs the substep rule of substeps.hpp.
void add_cloth_systems(Scheduler& scheduler, const ClothSolverSettings& settings = {});

}  // namespace drape
