// How many substeps a garment takes in one fixed step (method §3.4).
//
// Rule, per garment:
//   stability: n_s = ceil(fixed_dt / (safety * h_stable)), h_stable = m / k_drag, the bound
//              of eq. 2's explicit drag (the springs are constraints in compliance form,
//              stable at any stiffness: constraints.hpp); with the paper's integrator also
//              the explicit springs' bound (integrator.hpp spring_step_limit_s), and then
//              n_s is not capped by max_substeps but by max_stability_substeps;
//   motion:    n_m = ceil(fixed_dt * u / max_surface_travel), u the fastest surface speed
//              of a collider the garment can touch, relative to the garment's anchor
//              (|v_e - v_anchor(c_e)| + |w_e - w_anchor| * r_max), so that no collider
//              surface moves more than max_surface_travel through the cloth per substep;
//   n = clamp(max(n_s, n_m), 1, max_substeps), or `fixed_substeps` when that is set.
// The cloth step runs every garment with its own need (systems/cloth_systems.hpp).
// Walking adds a second substep when a thigh swings faster than ~2.4 m/s relative to the hips.
#pragma once

#include "drape/components/garment.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/cloth/garment_solver.hpp"

namespace drape {

struct ClothSolverSettings {
    Real stability_safety = Real(0.9);        ///< Fraction of the stability bound used.
    Real max_surface_travel_m = Real(0.04);   ///< Per substep.
    int max_substeps = 8;                     ///< Cap (cost bound when a body teleports).
    int fixed_substeps = 0;                   ///< > 0: always this many substeps (benchmarks, sweeps).
    /// The paper's integrator: a stable explicit step is its premise, so its stability need
    /// is not held to max_substeps; this only keeps an absurd stiffness from stalling a frame
    /// (1e6 N/m on the sample skirt needs about 800).
    int max_stability_substeps = 4096;
    /// Contact repair's rounds per garment per fixed step, shared out over its substeps (the
    /// cost bound of a garment caught on the body; GarmentCounters::budget_hits counts the
    /// substeps it stopped with springs still over the limit). docs/cloth.md "Contact repair".
    int repair_rounds_per_frame = 384;
};

/// Substeps one garment needs; also stores its needs in its counters and gives the solver
/// this step's contact repair budget.
int garment_substeps(const Registry& registry, Garment& garment, GarmentSolver& solver, double fixed_dt_s,
                     const ClothSolverSettings& settings);

}  // namespace drape
