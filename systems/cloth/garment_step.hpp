// One garment through one fixed step, in the order the cloth systems run it. Each stage
// function is the whole per-garment body of its system; `step_garment` runs them all for one
// garment by hand (tests, tools), so nothing needs a scheduler.
//
// Order of a fixed step (method §1 item 4):
//   begin_garment_step      counters restart, pin targets for the end of the step (§3.5)
//   for each substep:
//     integrate_garment     method §3.3-§3.4, then the pins
//     constrain_garment     method §4.1 warp, §4.2 weft
//     collide_garment_step  method §5, then the non-finite check
//   record_strain after the constraints of the last substep.
#pragma once

#include <functional>

#include "components/garment.hpp"
#include "engine/core/registry.hpp"
#include "systems/cloth/garment_solver.hpp"
#include "systems/cloth/substeps.hpp"

namespace drape {

/// Where a stage function is within the fixed step.
struct ClothSubstep {
    int index = 0;                    ///< Substep within the fixed step, [0, count).
    int count = 1;                    ///< Substeps in the fixed step.
    double fixed_dt_s = 1.0 / 60.0;   ///< The fixed step.
    double h_s = 1.0 / 60.0;          ///< fixed_dt_s / count.
    [[nodiscard]] bool last() const noexcept { return index + 1 >= count; }
};

/// Substep `index` of `count` in a fixed step of `fixed_dt_s`.
[[nodiscard]] ClothSubstep make_substep(int index, int count, double fixed_dt_s) noexcept;

/// Before the first substep: restarts the step's counters and sets the pins' targets.
void begin_garment_step(const Registry& registry, Garment& garment, GarmentSolver& solver, int substeps);

/// Forces and symplectic Euler on the integrated particles (simplified: layer 1; classic:
/// all), then pins.
void integrate_garment(const Registry& registry, Garment& garment, GarmentSolver& solver, const ClothSubstep& substep);

/// Provot on the warp; simplified: weft placement and Provot on the weft (§4.2); classic:
/// Provot on warp and weft.
void constrain_garment(Garment& garment, GarmentSolver& solver, const ClothSubstep& substep);

/// Collision against the colliders at the end of the substep, then the non-finite check:
/// a garment with a NaN or infinity is reported on stderr, counted, and reset.
void collide_garment_step(const Registry& registry, Garment& garment, GarmentSolver& solver,
                          const ClothSubstep& substep);

/// Records the largest warp/weft strain in the garment's counters (after the constraints
/// of the last substep).
void record_strain(Garment& garment);

/// Hooks for stepping by hand: each, when set, is called with the substep.
struct StepHooks {
    using Hook = std::function<void(Garment&, GarmentSolver&, const ClothSubstep&)>;
    Hook after_constraints;  ///< After constrain_garment.
    Hook collide;            ///< In place of collide_garment_step.
    Hook after_collision;    ///< After the collision stage.
};

/// One fixed step of one garment, exactly as the cloth systems run it (substeps from the
/// rule of substeps.hpp). Returns the substeps taken.
int step_garment(const Registry& registry, Garment& garment, GarmentSolver& solver, double fixed_dt_s,
                 const ClothSolverSettings& settings = {}, const StepHooks& hooks = {});

/// Back to rest around the body at its current place: the rest shape in the anchor's frame,
/// pins on their bindings, velocities those of the body, collision state cleared, pushed
/// out of the colliders.
void reset_garment_state(const Registry& registry, Garment& garment, GarmentSolver& solver);

/// Count of non-finite coordinates in x and v.
[[nodiscard]] std::uint64_t count_non_finite(const Garment& garment);

}  // namespace drape
