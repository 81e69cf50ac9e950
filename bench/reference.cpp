// Converged reference and restarted short horizons (see reference.hpp).
#include "bench/reference.hpp"

#include <cmath>

#include "bench/probe.hpp"
#include "bench/report.hpp"
#include "drape/components/garment.hpp"
#include "drape/systems/cloth/garment_config.hpp"

namespace drape::bench {

Result<HorizonStates> run_horizons(World& world, const HorizonPlan& plan, const HorizonStates* starts,
                                   const FrameHook& after_frame) {
    if (world.garments.empty()) return fail("horizons: the world has no garment");
    if (starts && (starts->start_x.size() < static_cast<std::size_t>(plan.horizons) ||
                   starts->start_v.size() < static_cast<std::size_t>(plan.horizons)))
        return fail("horizons: " + std::to_string(starts->start_x.size()) + " start states for " +
                    std::to_string(plan.horizons) + " horizons");
    const Entity entity = world.garments.front();
    HorizonStates out;
    out.end_x.resize(static_cast<std::size_t>(plan.horizons));
    for (int frame = 0; frame < plan.total_frames(); ++frame) {
        const int since = frame - plan.warmup_frames;
        if (since >= 0 && since % plan.horizon_frames == 0) {
            const auto h = static_cast<std::size_t>(since / plan.horizon_frames);
            const Garment& g = world.registry.get<Garment>(entity);
            const Matrix3X x = starts ? starts->start_x[h] : g.state.x;
            const Matrix3X v = starts ? starts->start_v[h] : g.state.v;
            if (auto ok = set_garment_state(world.registry, entity, x, v); !ok)
                return fail("horizon " + std::to_string(h) + ": " + ok.error().message);
            out.start_x.push_back(x);
            out.start_v.push_back(v);
        }
        const double before_ms = cloth_system_totals(world.scheduler).garment_ms;
        if (auto ok = step_world(world, plan.frame_dt_s); !ok) return fail("frame " + std::to_string(frame) + ": " + ok.error().message);
        if (after_frame) after_frame(world, frame, cloth_system_totals(world.scheduler).garment_ms - before_ms);
        const int done = frame + 1 - plan.warmup_frames;
        if (done > 0 && done % plan.horizon_frames == 0)
            out.end_x[static_cast<std::size_t>(done / plan.horizon_frames - 1)] = world.registry.get<Garment>(entity).state.x;
    }
    return out;
}

double horizon_rms_m(const HorizonStates& a, const HorizonStates& b) {
    if (a.end_x.size() != b.end_x.size() || a.end_x.empty()) return NAN;
    double sum = 0;
    Eigen::Index count = 0;
    for (std::size_t h = 0; h < a.end_x.size(); ++h) {
        if (a.end_x[h].cols() != b.end_x[h].cols() || a.end_x[h].cols() == 0) return NAN;
        sum += (a.end_x[h] - b.end_x[h]).cast<double>().colwise().squaredNorm().sum();
        count += a.end_x[h].cols();
    }
    const double rms = std::sqrt(sum / static_cast<double>(count));
    return std::isfinite(rms) ? rms : NAN;
}

Result<ConvergedReference> converged_reference(const WorldMaker& make, const HorizonPlan& plan, int first_substeps,
                                               int max_substeps, double tolerance_m) {
    if (first_substeps < 1 || 2 * first_substeps > max_substeps)
        return fail("reference: " + std::to_string(first_substeps) + " substeps cannot be doubled within " +
                    std::to_string(max_substeps));
    auto run = [&](int substeps, const HorizonStates* starts) -> Result<HorizonStates> {
        auto world = make(substeps);
        if (!world) return fail("reference at " + std::to_string(substeps) + " substeps: " + world.error().message);
        auto states = run_horizons(*world, plan, starts);
        if (!states) return fail("reference at " + std::to_string(substeps) + " substeps: " + states.error().message);
        return states;
    };
    auto coarse = run(first_substeps, nullptr);
    if (!coarse) return fail(coarse.error().message);
    ConvergedReference ref;
    HorizonStates current = std::move(*coarse);
    HorizonStates best;
    double best_m = INFINITY;
    for (int substeps = first_substeps;; substeps *= 2) {
        auto finer = run(2 * substeps, &current);
        if (!finer) return fail(finer.error().message);
        const double distance = horizon_rms_m(current, *finer);
        ref.ladder.push_back({substeps, distance});
        if (distance < best_m || !std::isfinite(best_m)) {
            best_m = distance;
            best = current;
            ref.substeps = substeps;
        }
        // A first-order method halves the distance with each doubling; one that does not shrink
        // it by a quarter is not converging, and finer steps only cost more.
        const bool shrinking = ref.ladder.size() < 2 || distance < 0.75 * ref.ladder[ref.ladder.size() - 2].against_double_m;
        if (distance < tolerance_m || !shrinking || 4 * substeps > max_substeps) break;
        // The finer run is the next candidate; its horizons started from the same states.
        current.end_x = std::move(finer->end_x);
    }
    ref.states = std::move(best);
    ref.converged_m = best_m;
    ref.converged = best_m < tolerance_m;

    // A micrometre moved at each start: what the horizon makes of a tiny difference.
    HorizonStates moved = ref.states;
    std::uint32_t seed = 1;
    for (Matrix3X& x : moved.start_x)
        x = x.unaryExpr([&](Real value) {
            seed = seed * 1664525u + 1013904223u;   // a fixed pseudo-random +-1 um per coordinate
            return value + Real(((seed >> 8) & 1u) ? 1e-6 : -1e-6);
        });
    auto perturbed = run(ref.substeps, &moved);
    if (!perturbed) return fail(perturbed.error().message);
    ref.perturbed_m = horizon_rms_m(ref.states, *perturbed);
    return ref;
}

nlohmann::json reference_json(const ConvergedReference& reference) {
    nlohmann::json ladder = nlohmann::json::array();
    for (const ReferenceRung& r : reference.ladder)
        ladder.push_back({{"substeps", r.substeps},
                          {"against_double_m", std::isfinite(r.against_double_m) ? nlohmann::json(r.against_double_m) : nlohmann::json()}});
    return {{"converged_m", std::isfinite(reference.converged_m) ? nlohmann::json(reference.converged_m) : nlohmann::json()},
            {"substeps", reference.substeps},
            {"converged", reference.converged},
            {"perturbed_1um_m", std::isfinite(reference.perturbed_m) ? nlohmann::json(reference.perturbed_m) : nlohmann::json()},
            {"ladder", std::move(ladder)}};
}

nlohmann::json horizon_plan_json(const HorizonPlan& plan) {
    return {{"warmup_frames", plan.warmup_frames},
            {"horizons", plan.horizons},
            {"horizon_frames", plan.horizon_frames},
            {"frame_dt_s", plan.frame_dt_s}};
}

std::string horizon_plan_text(const HorizonPlan& plan) {
    return "Cloth on a walking body is chaotic, so distances are measured over short horizons: after " +
           std::to_string(plan.warmup_frames) + " warm-up frames, at the start of each of " + std::to_string(plan.horizons) +
           " back-to-back horizons of " + std::to_string(plan.horizon_frames) + " frames (" +
           fixed(plan.horizon_frames * plan.frame_dt_s, 3) +
           " s) the garment is given the reference's particle positions and velocities, both step the same body "
           "motion, and every particle's distance from the same particle of the reference is taken at the horizon's "
           "end; the figure is the RMS over particles and horizons.";
}

std::string reference_text(const ConvergedReference& reference, double tolerance_m) {
    std::string ladder;
    for (const ReferenceRung& r : reference.ladder)
        ladder += (ladder.empty() ? "" : "; ") + std::to_string(r.substeps) + " substeps: " +
                  fixed(1000 * r.against_double_m, 3) + " mm from " + std::to_string(2 * r.substeps);
    std::string text = "Refinement ladder (RMS distance over the horizons between the run at n substeps and the run at 2n, "
                       "both restarted from the same states): " + ladder + ". ";
    if (reference.converged)
        text += "The reference is the run at **" + std::to_string(reference.substeps) + " substeps**: doubling its "
                "substeps moves it by **" + fixed(1000 * reference.converged_m, 3) + " mm** RMS (`converged_m`), under "
                "the " + fixed(1000 * tolerance_m, 1) + " mm required.";
    else
        text += "**The reference did not converge**: the closest rung, " + std::to_string(reference.substeps) +
                " substeps, is still " + fixed(1000 * reference.converged_m, 3) + " mm RMS from its refinement "
                "(`converged_m`), above the " + fixed(1000 * tolerance_m, 1) + " mm required; it is used as the "
                "reference, and distances from it below that figure are not resolved.";
    text += " Started from positions moved by 1 micrometre, the reference ends its horizons " +
            fixed(1000 * reference.perturbed_m, 3) + " mm RMS from itself: what a horizon makes of a tiny difference.";
    return text;
}

}  // namespace drape::bench
