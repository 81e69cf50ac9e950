// One garment through one fixed step, in the order the cloth systems run it. Each stage
// function is the per-garment body of its system; `step_garment` runs them all for one
// garment by hand (tests, tools), so nothing needs a scheduler.
//
// Order of a fixed step (method §1 item 4; docs/cloth.md "Solver"):
//   begin_garment_step        counters restart, pin targets for the end of the step (§3.5)
//   for each substep:
//     integrate_garment       cloth_integration: eq. 2 prediction (§3.3-§3.4) of the
//                             integrated particles, layer 2 carried by layer 1 (simplified,
//                             §4.2), then the pins
//     prepare_collision       cloth_collision: colliders at the end of the substep
//     `rounds` times:
//       constrain_round       cloth_constraint: springs with Provot's limit (§4.1, §4.2);
//                             in the last round then the tethers
//       collide_round         cloth_collision, after every second round and the last
//                             (collides_after): candidate lists brought up to date, then
//                             every particle out of the ellipsoids (§5), positions only
//     finish_constraints      cloth_constraint: Provot's limit along every warp line from
//                             the pins down, then along every weft row (constraints.hpp
//                             limit_warp_lines, limit_weft_rows)
//     finish_collision        cloth_collision: a last collision round, contact repair
//                             (rounds of limits and collision where a push left a spring over
//                             the limit), then the velocities of the free particles from the
//                             substep's move (less the push-outs and the warp limit's moves;
//                             at contacts no approach, friction), then the non-finite check
#pragma once

#include <functional>

#include "drape/components/garment.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/cloth/garment_solver.hpp"
#include "drape/systems/cloth/substeps.hpp"

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

/// Eq. 2's prediction of the integrated particles (simplified: layer 1; classic: all) relative
/// to the anchor frame (integrator.hpp), then the pins.
void integrate_garment(const Registry& registry, Garment& garment, GarmentSolver& solver, const ClothSubstep& substep);

/// Places the colliders at the end of the substep.
void prepare_collision(const Registry& registry, Garment& garment, GarmentSolver& solver, const ClothSubstep& substep);

/// One Gauss-Seidel round of springs with Provot's limit; in the last round then the tethers
/// (constraints.hpp). The rounds of a substep run in order, 0 first: between two rounds
/// with no collision round between them the positions stay in solver.x_rows, and the
/// garment's x is written only where a collision round follows (collides_after) and after
/// the last round.
void constrain_round(Garment& garment, GarmentSolver& solver, const ClothSubstep& substep, int round);

/// One round of collision of every particle, positions only.
void collide_round(const Registry& registry, Garment& garment, GarmentSolver& solver, const ClothSubstep& substep,
                   int round);

/// After the rounds: Provot's limit along every warp line, one-sided from the pins down,
/// then along every weft row (constraints.hpp limit_warp_lines, limit_weft_rows); their
/// moves are kept.
void finish_constraints(Garment& garment, GarmentSolver& solver, const ClothSubstep& substep);

/// After finish_constraints: a last collision round (the limits moved particles), then
/// contact repair: rounds of the limits on the lines and rows where a particle that moved
/// has a spring over the strain limit (particles the collision pushed weighted as heavy)
/// and a collision of what they moved, until none has or the fixed step's round budget is spent
/// (ClothSolverSettings::repair_rounds_per_frame, shared over the substeps left; docs/cloth.md);
/// then the velocities of the free particles from their move over the substep: the warp limit's
/// move of the particle below on the line given back (dynamic follow-the-leader), the
/// push-outs left out; where a particle touched an ellipsoid, no velocity toward it relative
/// to its surface and Coulomb friction. Then the non-finite check: a garment with a NaN or
/// infinity is reported on stderr, counted, and reset.
void finish_collision(const Registry& registry, Garment& garment, GarmentSolver& solver, const ClothSubstep& substep);

/// Constraint rounds per substep of the garment's material.
[[nodiscard]] int constraint_rounds(const Garment& garment) noexcept;

/// Constraint rounds per collision round: the collision system runs after every second
/// constraint round, counted back from the last, so that the last round always ends in one.
/// Measured on the sample scene's walk (docs/cloth.md): a collision round after every
/// constraint round cost a quarter more per frame for no better strain or penetration
/// after the frame.
inline constexpr int constraint_rounds_per_collision = 2;

/// Whether a collision round follows constraint round `round` of `rounds`.
[[nodiscard]] bool collides_after(int round, int rounds) noexcept;

/// Hooks for stepping by hand: each, when set, is called with the substep.
struct StepHooks {
    using Hook = std::function<void(Garment&, GarmentSolver&, const ClothSubstep&)>;
    Hook collide_round;      ///< In place of each collide_round of the rounds.
    Hook after_constraints;  ///< After finish_constraints.
    Hook finish_collision;   ///< In place of finish_collision.
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
