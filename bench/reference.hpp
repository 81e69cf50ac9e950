// A converged reference garment and the short horizons a configuration is compared with it
// over (`drape bench error`, `drape bench quality`).
//
// Cloth on a walking body is chaotic: two solvers that start together drift apart within a
// second whatever their accuracy, so a long run measures the chaos, not the solver. The
// comparison is made over short horizons instead: after `warmup_frames`, at the start of each
// of `horizons` back-to-back horizons of `horizon_frames` frames, the compared garment is
// given the reference garment's positions and velocities (set_garment_state), both step the
// same body motion for the horizon, and the particles' distances at its end are taken.
//
// The reference is the classic model with brute-force collision at a fixed, fine substep
// count, chosen by its own convergence: its end states are compared, over the same restarted
// horizons, with those of a run at twice the substeps (`converged_m`). The substeps double
// until that RMS distance falls below the tolerance (1 mm). When a doubling no longer shrinks
// it by a quarter (a first-order method halves it), or at a cap, the ladder stops (finer steps
// would only cost more) and the rung closest to its refinement is the reference, marked as
// not converged; reports show the whole ladder. The horizons' start states are those of the
// first, coarsest reference run; every finer run, and every compared configuration, is
// restarted from them. A run of the reference restarted from starts moved by 1 micrometre
// shows how much a horizon amplifies a tiny difference.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/math.hpp"
#include "drape/game/world.hpp"

namespace drape::bench {

/// Frames of a horizon comparison.
struct HorizonPlan {
    int warmup_frames = 60;                 ///< Frames before the first horizon (from the rest shape).
    int horizons = 6;                       ///< Back-to-back horizons after the warm-up.
    int horizon_frames = 10;                ///< Frames of one horizon (10 = 1/6 s).
    double frame_dt_s = 1.0 / 60.0;

    [[nodiscard]] int total_frames() const noexcept { return warmup_frames + horizons * horizon_frames; }
    /// The frame at which horizon `h` starts (the state before that frame is stepped).
    [[nodiscard]] int horizon_start(int h) const noexcept { return warmup_frames + h * horizon_frames; }
};

/// The first garment's state at the start and at the end of each horizon.
struct HorizonStates {
    std::vector<Matrix3X> start_x, start_v;  ///< What each horizon started from.
    std::vector<Matrix3X> end_x;             ///< Positions after its `horizon_frames` frames.
};

/// Called after every frame of a run with the frame's index (0-based) and the garment
/// simulation's milliseconds for that frame (frame profiler).
using FrameHook = std::function<void(World& world, int frame, double garment_ms)>;

/// Steps `world` through `plan`. At each horizon start its first garment is given the state
/// of `starts` (nullptr: its own state, so that a reference run is restarted exactly as
/// the runs compared with it). Returns the start and end states.
[[nodiscard]] Result<HorizonStates> run_horizons(World& world, const HorizonPlan& plan, const HorizonStates* starts,
                                                 const FrameHook& after_frame = {});

/// RMS over horizons and particles of the distance between the end positions of `a` and
/// `b`; NaN when they do not match (count or size) or hold a non-finite value.
[[nodiscard]] double horizon_rms_m(const HorizonStates& a, const HorizonStates& b);

/// Builds the world a horizon run steps, with `substeps` fixed substeps per frame.
using WorldMaker = std::function<Result<World>(int substeps)>;

/// One rung of the reference's refinement ladder.
struct ReferenceRung {
    int substeps = 0;
    double against_double_m = 0;  ///< RMS distance to the run at twice the substeps.
};

/// The reference a comparison is measured against.
struct ConvergedReference {
    HorizonStates states;         ///< Start states (of the coarsest run) and the reference's end states.
    int substeps = 0;             ///< The reference's fixed substeps per frame.
    double converged_m = 0;       ///< RMS distance between it and its refinement (2 x substeps).
    bool converged = false;       ///< converged_m < the tolerance.
    double perturbed_m = 0;       ///< RMS distance between it and itself restarted from starts moved by 1 um.
    std::vector<ReferenceRung> ladder;  ///< Every substep count tried, coarsest first.
};

/// Doubles the substeps from `first_substeps` until the run at n substeps and the one at 2n
/// end their horizons within `tolerance_m` RMS; stops without convergence once a doubling
/// shrinks that distance by less than a quarter, or when 2n would exceed `max_substeps`, and
/// then returns the rung closest to its refinement with converged = false. `make` builds the reference world.
[[nodiscard]] Result<ConvergedReference> converged_reference(const WorldMaker& make, const HorizonPlan& plan,
                                                             int first_substeps, int max_substeps,
                                                             double tolerance_m = 1e-3);

/// `{"converged_m", "substeps", "converged", "perturbed_1um_m", "ladder": [{"substeps", "against_double_m"}]}`.
[[nodiscard]] nlohmann::json reference_json(const ConvergedReference& reference);
/// `{"warmup_frames", "horizons", "horizon_frames", "frame_dt_s"}`.
[[nodiscard]] nlohmann::json horizon_plan_json(const HorizonPlan& plan);
/// How the horizons are run, in a sentence or two for a report.
[[nodiscard]] std::string horizon_plan_text(const HorizonPlan& plan);
/// The reference's ladder and verdict for a report ("16 substeps: 2.1 mm from 32; ...").
[[nodiscard]] std::string reference_text(const ConvergedReference& reference, double tolerance_m);

}  // namespace drape::bench
