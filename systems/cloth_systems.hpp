// The cloth step: the cloth module's one entry in the scheduler (phase simulation).
//
// Each fixed step it gathers the garments (creating a solver for a garment that has none)
// and steps each garment through all its substeps before the next (in parallel over
// garments), with its own substep count by the rule in systems/cloth/substeps.hpp (or
// ClothSolverSettings::fixed_substeps) and its own rounds; in every substep the three cloth
// systems in the order of systems/cloth/garment_step.hpp:
//   cloth_integration  (cloth_integration_system.hpp)  method §3.3-§3.5
//   then rounds of
//   cloth_constraint   (cloth_constraint_system.hpp)   method §4
//   cloth_collision    (cloth_collision_system.hpp)    method §5 (every second round)
//   and each of the last two once more to finish the substep.
// The scheduler times the whole step as "cloth"; each system is timed in a profiler slot of
// its own under it, so the frame budget lists all four. A garment stepping alone has every
// system call timed; with several in parallel, each system's slot gets the step's wall time
// shared out by the systems' time summed over the threads (one run per fixed step).
#pragma once

#include "drape/engine/core/scheduler.hpp"
#include "drape/systems/cloth/substeps.hpp"

namespace drape {

/// Adds the cloth step to `scheduler`. Returns its profiler slot.
std::uint32_t add_cloth_systems(Scheduler& scheduler, const ClothSolverSettings& settings = {});

/// Every garment of `registry` through one fixed step of `fixed_dt_s`, as the cloth step runs
/// it, without timing (tools that drive the cloth themselves).
void step_cloth(Registry& registry, double fixed_dt_s, const ClothSolverSettings& settings = {});

}  // namespace drape
