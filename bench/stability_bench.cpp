// `drape bench stability`: stiff and extreme cases.
//
// Matrix: spring stiffness x step (the fixed simulation step, one frame each) x motion x
// garment, with the cloth's automatic substeps (method §3.4) and with one substep per step.
// A case is unstable on any non-finite value (the cloth resets such a garment and counts
// it), energy growth (the garment's kinetic energy in the last third of the run more than
// 10x its peak in the middle third, and above 0.05 J), a structural spring longer than
// 1.5 x its rest length after a frame, or a particle more than 1 m from the body's
// ellipsoids. Each case runs the walking default avatar for max(16 steps, 0.75 s).
#include <algorithm>
#include <cstdio>
#include <cmath>
#include <limits>
#include <numbers>

#include "bench/probe.hpp"
#include "bench/report.hpp"
#include "bench/world.hpp"
#include "components/animation_player.hpp"
#include "components/transform.hpp"
#include "systems/cloth/integrator.hpp"
#include "systems/cloth/substeps.hpp"

namespace drape::bench {

namespace {

enum class Motion { walk, run, spin, teleport, time_scale, sudden_stop };
constexpr Motion motions[] = {Motion::walk, Motion::run, Motion::spin, Motion::teleport, Motion::time_scale,
                              Motion::sudden_stop};
const char* motion_name(Motion m) {
    switch (m) {
        case Motion::walk: return "walk";
        case Motion::run: return "run";
        case Motion::spin: return "spin";
        case Motion::teleport: return "teleport";
        case Motion::time_scale: return "time_scale_10x";
        case Motion::sudden_stop: return "sudden_stop";
    }
    return "?";
}

constexpr double stiffnesses[] = {10, 1e2, 1e3, 1e4, 1e5, 1e6};
/// The dress has 12x the skirt's particles; it runs a coarser stiffness set to keep the
/// benchmark within minutes.
constexpr double dress_stiffnesses[] = {10, 1e3, 1e6};
std::vector<double> stiffness_set(GarmentType g) {
    if (g == GarmentType::dress) return {std::begin(dress_stiffnesses), std::end(dress_stiffnesses)};
    return {std::begin(stiffnesses), std::end(stiffnesses)};
}
constexpr double steps_s[] = {1.0 / 240, 1.0 / 60, 1.0 / 15, 1.0 / 4};
const char* step_label(double dt) {
    if (dt < 0.005) return "1/240";
    if (dt < 0.02) return "1/60";
    if (dt < 0.1) return "1/15";
    return "1/4";
}

struct Case {
    std::string name;
    double stiffness, frame_dt_s;
    Motion motion;
    GarmentType garment;
    bool auto_substeps;
    bool stable = true;
    double max_strain = 0;
    std::string reason;
    double bound_simple_s = 0;     ///< 2 sqrt(m/k).
    double bound_cloth_s = 0;      ///< The cloth's Gershgorin bound (stable_step_s).
    double mean_substeps = 0;
};

double kinetic_energy(const Garment& g) {
    double e = 0;
    for (Eigen::Index i = 0; i < g.state.x.cols(); ++i)
        if (g.state.inv_mass[i] > 0) e += 0.5 / g.state.inv_mass[i] * g.state.v.col(i).squaredNorm();
    return e;
}

/// Distance of the farthest particle from the nearest collider surface (approximated by
/// the centre distance minus the largest radius).
double farthest_from_body(const Garment& g, const std::vector<Affine3>& colliders) {
    double farthest = 0;
    for (Eigen::Index i = 0; i < g.state.x.cols(); ++i) {
        double nearest = INFINITY;
        for (const auto& c : colliders) {
            const double radius = std::max({c.linear().col(0).norm(), c.linear().col(1).norm(), c.linear().col(2).norm()});
            nearest = std::min(nearest, (g.state.x.col(i) - c.translation()).norm() - radius);
        }
        if (!std::isfinite(nearest)) return INFINITY;
        farthest = std::max(farthest, nearest);
    }
    return farthest;
}

/// Runs one case on a world built for its garment and step.
Result<void> run_case(World& world, Case& c) {
    Registry& r = world.registry;
    const Entity character = world.characters.at(0);
    auto& transform = r.get<Transform>(character);
    auto& player = r.get<AnimationPlayer>(character);
    const Transform home = transform;
    player.speed = c.motion == Motion::run ? 2.5 : 1.0;
    player.playing = true;
    if (auto ok = set_time_scale(world, c.motion == Motion::time_scale ? 10.0 : 1.0); !ok) return fail(ok.error().message);
    Garment& g0 = first_garment(world);
    g0.config.material.stretch_N_m = static_cast<Real>(c.stiffness);
    reset_garments(world);
    {
        const Garment& g = first_garment(world);
        double m = 0;
        for (Eigen::Index i = 0; i < g.state.inv_mass.size(); ++i)
            if (g.state.inv_mass[i] > 0) {
                m = 1.0 / g.state.inv_mass[i];
                break;
            }
        c.bound_simple_s = 2 * std::sqrt(m / c.stiffness);
        c.bound_cloth_s = std::numeric_limits<double>::infinity();  // springs in compliance form: no bound
    }
    const auto springs = structural_springs(*first_garment(world).fabric);
    const std::uint64_t nonfinite_before = first_garment(world).counters.non_finite_values;

    const int frames = std::max(16, static_cast<int>(std::lround(0.75 / c.frame_dt_s)));
    const int event = frames / 3;
    double middle_peak = 0, late_peak = 0, substeps = 0;
    for (int f = 0; f < frames; ++f) {
        switch (c.motion) {
            case Motion::spin:
                transform.rotation = Quat(Eigen::AngleAxis<Real>(static_cast<Real>(30.0 * c.frame_dt_s), Vec3::UnitY())) *
                                     transform.rotation;
                break;
            case Motion::teleport:
                if (f == event) transform.position += Vec3(100, 0, 0);
                break;
            case Motion::sudden_stop:
                if (f < event)
                    transform.position += Vec3(0, 0, static_cast<Real>(5.0 * c.frame_dt_s));   // 5 m/s forward
                else
                    player.playing = false;   // stops dead: no travel, no animation
                break;
            default: break;
        }
        if (auto ok = step_world(world, c.frame_dt_s); !ok) return fail(ok.error().message);
        const Garment& g = first_garment(world);
        substeps += g.counters.substeps;
        if (g.counters.non_finite_values > nonfinite_before || !g.state.x.allFinite() || !g.state.v.allFinite()) {
            c.stable = false;
            c.reason = "non-finite values (frame " + std::to_string(f) + ")";
            break;
        }
        const double strain = max_strain(g.state.x, springs.springs, springs.rest_m);
        c.max_strain = std::max(c.max_strain, strain);
        const double energy = kinetic_energy(g);
        if (f >= frames / 3 && f < 2 * frames / 3) middle_peak = std::max(middle_peak, energy);
        if (f >= 2 * frames / 3) late_peak = std::max(late_peak, energy);
        const double distance = farthest_from_body(g, collider_worlds(r, g));
        if (distance > 1.0) {
            c.stable = false;
            c.reason = "particle " + fixed(distance, 2) + " m from the body (frame " + std::to_string(f) + ")";
            break;
        }
    }
    c.mean_substeps = substeps / frames;
    if (c.stable && late_peak > 10 * middle_peak && late_peak > 0.05) {
        c.stable = false;
        c.reason = "energy growth (" + fixed(late_peak, 3) + " J late vs " + fixed(middle_peak, 3) + " J)";
    }
    if (c.stable && c.max_strain > 0.5) {
        c.stable = false;
        c.reason = "strain " + fixed(100 * c.max_strain, 0) + " %";
    }
    transform = home;
    player.playing = true;
    player.speed = 1;
    if (auto ok = set_time_scale(world, 1.0); !ok) return fail(ok.error().message);
    return {};
}

}  // namespace

Result<void> run_stability(const BenchOptions& options) {
    const Machine machine = describe_machine();
    std::vector<Case> cases;
    for (GarmentType garment : {GarmentType::skirt, GarmentType::dress}) {
        for (double dt : steps_s) {
            std::fprintf(stderr, "drape bench stability: %s, step %s s\n", garment_type_name(garment), step_label(dt));
            for (bool automatic : {true, false}) {
                WorldSpec spec;
                spec.garment = garment;
                spec.fixed_dt_s = dt;
                spec.threads = options.threads;
                spec.substeps = automatic ? 0 : 1;
                auto world = build_bench_world(spec);
                if (!world) return fail("stability: " + world.error().message);
                for (double k : stiffness_set(garment))
                    for (Motion motion : motions) {
                        Case c;
                        c.stiffness = k;
                        c.frame_dt_s = dt;
                        c.motion = motion;
                        c.garment = garment;
                        c.auto_substeps = automatic;
                        c.name = std::string(garment_type_name(garment)) + "/" + motion_name(motion) + "/k=" +
                                 fixed(k, 0) + "/dt=" + step_label(dt) + (automatic ? "/auto" : "/1-substep");
                        if (auto ok = run_case(*world, c); !ok) return fail("stability: " + c.name + ": " + ok.error().message);
                        cases.push_back(c);
                    }
            }
        }
    }

    int unstable_with_auto = 0, diverged_with_auto = 0;
    for (const auto& c : cases)
        if (c.auto_substeps && !c.stable) {
            ++unstable_with_auto;
            if (c.reason.rfind("strain", 0) != 0) ++diverged_with_auto;
        }

    nlohmann::json json;
    json["cases"] = nlohmann::json::array();
    for (const auto& c : cases)
        json["cases"].push_back({{"name", c.name},
                                 {"stiffness", c.stiffness},
                                 {"frame_dt_s", c.frame_dt_s},
                                 {"motion", motion_name(c.motion)},
                                 {"garment", garment_type_name(c.garment)},
                                 {"auto_substeps", c.auto_substeps},
                                 {"stable", c.stable},
                                 {"max_strain", c.max_strain},
                                 {"reason", c.reason}});
    json["unstable_with_auto"] = unstable_with_auto;

    Report report("Stability on stiff and extreme cases (`stability`)", options, machine);
    report.paragraph(
        "The walking default avatar wears the default skirt (837 particles) or dress (10,080). Matrix: stretch-spring "
        "stiffness {10, 100, 1e3, 1e4, 1e5, 1e6} N/m (dress: {10, 1e3, 1e6}, to keep the run within minutes) x step {1/240, 1/60, 1/15, 1/4} s (the fixed simulation step; one "
        "frame per step) x motion x garment, with the cloth's automatic substeps and with one substep per step. "
        "Motions: walk; run (the walk clip at 2.5x speed); spin (the character turned at 30 rad/s about the vertical); "
        "teleport (moved 100 m at a third of the run); 10x time scale; sudden stop (carried forward at 5 m/s, then "
        "stopped dead with the animation paused at a third of the run). A case is unstable on any non-finite value, "
        "energy growth (kinetic energy in the last third above 10x its peak in the middle third and above 0.05 J), "
        "a structural spring longer than 1.5x its rest length after a frame, or a particle more than 1 m from the "
        "body's ellipsoids; the reason is the first that tripped. Each case runs max(16 steps, 0.75 s). Strain is "
        "measured after the whole frame (collision included), on the springs of both layers.");
    report.heading("Summary");
    report.paragraph("Unstable with automatic substeps: **" + std::to_string(unstable_with_auto) + "** of " +
                     std::to_string(cases.size() / 2) + " cases (" + std::to_string(diverged_with_auto) +
                     " by divergence: non-finite values, energy growth or distance; the rest by strain above 50 %).");
    report.targets({upper_bound_target("cases unstable with automatic substeps", unstable_with_auto, 0, "", 0)});

    // Stable motions per cell: rows garment x auto x stiffness, columns steps.
    std::vector<std::vector<std::string>> summary;
    for (GarmentType garment : {GarmentType::skirt, GarmentType::dress})
        for (bool automatic : {true, false})
            for (double k : stiffness_set(garment)) {
                std::vector<std::string> row{garment_type_name(garment), automatic ? "auto" : "1", fixed(k, 0)};
                for (double dt : steps_s) {
                    int stable = 0, bounded = 0, total = 0;
                    double substeps = 0;
                    for (const auto& c : cases)
                        if (c.garment == garment && c.auto_substeps == automatic && c.stiffness == k && c.frame_dt_s == dt) {
                            ++total;
                            stable += c.stable ? 1 : 0;
                            bounded += (c.stable || c.reason.rfind("strain", 0) == 0) ? 1 : 0;
                            substeps += c.mean_substeps;
                        }
                    row.push_back(std::to_string(stable) + "/" + std::to_string(bounded) + "/" + std::to_string(total) +
                                  (automatic ? " (" + fixed(substeps / std::max(1, total), 1) + " sub)" : ""));
                }
                summary.push_back(row);
            }
    report.paragraph("Per cell: stable / not diverged (stable, or unstable only by strain) / motions run; with automatic "
                     "substeps the mean substeps per step in brackets:");
    report.table({"garment", "substeps", "k (N/m)", "h = 1/240 s", "h = 1/60 s", "h = 1/15 s", "h = 1/4 s"}, summary);

    report.heading("Where the explicit scheme breaks (one substep per step)");
    report.paragraph(
        "For a spring of stiffness k between masses m, symplectic Euler is stable for roughly h < 2 sqrt(m/k) "
        "(method §3.4); the cloth's own bound (stable_step_s) is the Gershgorin bound over every spring of a "
        "particle, h < 2 / sqrt(lambda_max(M^-1 K)), smaller by about 2x for a particle between two springs. Walk "
        "only; \"diverged\" counts non-finite values, energy growth or distance, not strain.");
    std::vector<std::vector<std::string>> bound_rows;
    for (const auto& c : cases) {
        if (c.auto_substeps || c.motion != Motion::walk) continue;
        const bool diverged = !c.stable && c.reason.rfind("strain", 0) != 0;
        bound_rows.push_back({garment_type_name(c.garment), fixed(c.stiffness, 0), step_label(c.frame_dt_s),
                              fixed(1000 * c.bound_simple_s, 3), fixed(1000 * c.bound_cloth_s, 3),
                              fixed(c.frame_dt_s / c.bound_simple_s, 2), c.stable ? "stable" : (diverged ? "**diverged**" : "strain"),
                              c.reason});
    }
    report.table({"garment", "k (N/m)", "h (s)", "2 sqrt(m/k) (ms)", "cloth bound (ms)", "h / 2 sqrt(m/k)", "outcome", "reason"},
                 bound_rows);

    // Plot: stability map (one substep, walk), h against k, with both bounds.
    std::vector<PlotData> data;
    PlotData stable_points{"stable", {}}, unstable_points{"unstable", {}}, simple{"simple", {}}, cloth{"cloth", {}};
    for (const auto& c : cases) {
        if (c.auto_substeps || c.motion != Motion::walk || c.garment != GarmentType::skirt) continue;
        const bool diverged = !c.stable && c.reason.rfind("strain", 0) != 0;
        (diverged ? unstable_points : stable_points).rows.push_back({c.stiffness, 1000 * c.frame_dt_s});
        simple.rows.push_back({c.stiffness, 1000 * c.bound_simple_s});
        cloth.rows.push_back({c.stiffness, 1000 * c.bound_cloth_s});
    }
    if (stable_points.rows.empty()) stable_points.rows.push_back({NAN, NAN});
    if (unstable_points.rows.empty()) unstable_points.rows.push_back({NAN, NAN});
    data = {stable_points, unstable_points, simple, cloth};
    const std::string script =
        "set title 'Skirt, one substep per step, walking: where symplectic Euler diverges'\n"
        "set xlabel 'spring stiffness k (N/m)'\nset ylabel 'step h (ms)'\nset logscale xy\nset grid\nset key outside right\n"
        "plot $stable using 1:2 with points pt 7 ps 1.5 lc rgb '#30a050' title 'not diverged', "
        "$unstable using 1:2 with points pt 2 ps 2 lw 2 lc rgb '#c03020' title 'diverged', "
        "$simple using 1:2 smooth unique with lines lw 2 lc rgb '#3060c0' title 'h = 2 sqrt(m/k)', "
        "$cloth using 1:2 smooth unique with lines dt 2 lw 2 lc rgb '#202020' title 'cloth bound (Gershgorin)'\n";
    report.plot("stability.png", "Stability map: step against stiffness", data, script, 1000, 560);

    report.heading("Unstable cases with automatic substeps");
    std::vector<std::vector<std::string>> unstable_rows;
    for (const auto& c : cases)
        if (c.auto_substeps && !c.stable)
            unstable_rows.push_back({c.name, fixed(c.mean_substeps, 1), fixed(100 * c.max_strain, 0), c.reason});
    if (unstable_rows.empty())
        report.paragraph("None.");
    else
        report.table({"case", "substeps / step", "max strain (%)", "reason"}, unstable_rows);

    return finish(report, options, json);
}

}  // namespace drape::bench
