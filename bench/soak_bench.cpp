// `drape bench soak`: the sample scene (default avatar walking in place in the default
// skirt, headless) for an hour of simulated time at 60 frames per second, reporting drift
// every simulated minute: whether the garment is still on the body (farthest particle
// from the hip ellipsoid's centre, deepest penetration), worst strain, kinetic energy
// (mean and peak per minute: it must not grow), non-finite values and resets.
//
// DRAPE_SOAK_MINUTES (1..600, default 60) shortens or lengthens the run.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "bench/probe.hpp"
#include "bench/report.hpp"
#include "bench/world.hpp"
#include "drape/components/ellipsoid_collider.hpp"
#include "drape/systems/cloth/garment_quality.hpp"
#include "drape/systems/cloth/integrator.hpp"

namespace drape::bench {

namespace {

struct Minute {
    int minute = 0;                 ///< 1-based.
    double farthest_from_hip_m = 0; ///< Worst over the minute.
    double max_penetration_m = 0;   ///< Worst the collision system found (before response).
    double max_strain = 0;          ///< Worst structural strain after a whole frame.
    double mean_energy_J = 0;       ///< Kinetic energy, mean over the minute's frames.
    double peak_energy_J = 0;
    std::uint64_t nonfinite = 0;    ///< Non-finite values the cloth found this minute.
    std::uint64_t resets = 0;       ///< Garment resets this minute.
    std::uint64_t teleports = 0;
    double wall_s = 0;              ///< Wall time the minute took.
};

double kinetic_energy(const Garment& g) {
    double e = 0;
    for (Eigen::Index i = 0; i < g.state.x.cols(); ++i)
        if (g.state.inv_mass[i] > 0) e += 0.5 / g.state.inv_mass[i] * g.state.v.col(i).squaredNorm();
    return e;
}

Result<int> soak_minutes() {
    const char* text = std::getenv("DRAPE_SOAK_MINUTES");
    if (!text || !*text) return 60;
    char* end = nullptr;
    const long m = std::strtol(text, &end, 10);
    if (*end != '\0' || m < 1 || m > 600)
        return fail(std::string("DRAPE_SOAK_MINUTES: must be an integer in [1, 600], got '") + text + "'");
    return static_cast<int>(m);
}

/// Mean of a member over minutes [first, last).
template <class F>
double mean_over(const std::vector<Minute>& minutes, std::size_t first, std::size_t last, F f) {
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t i = first; i < last && i < minutes.size(); ++i, ++n) sum += f(minutes[i]);
    return n ? sum / static_cast<double>(n) : 0;
}

}  // namespace

Result<void> run_soak(const BenchOptions& options) {
    auto minutes_total = soak_minutes();
    if (!minutes_total) return fail(minutes_total.error().message);
    const Machine machine = describe_machine();

    WorldSpec spec;
    spec.threads = options.threads;
    spec.profile = false;
    auto world = build_bench_world(spec);
    if (!world) return fail("soak: " + world.error().message);
    const double frame_dt_s = spec.fixed_dt_s;
    const int frames_per_minute = static_cast<int>(std::lround(60.0 / frame_dt_s));
    const std::size_t particles = static_cast<std::size_t>(first_garment(*world).state.x.cols());

    std::vector<Minute> minutes;
    std::uint64_t nonfinite_seen = first_garment(*world).counters.non_finite_values;
    std::uint64_t resets_seen = first_garment(*world).counters.resets;
    std::uint64_t teleports_seen = world->teleports->teleports;
    std::uint64_t frames_left_nonfinite = 0;   // frames ending with a non-finite value left in the world
    const auto start_all = now_ns();
    for (int m = 1; m <= *minutes_total; ++m) {
        Minute row;
        row.minute = m;
        const auto start = now_ns();
        double energy_sum = 0;
        for (int f = 0; f < frames_per_minute; ++f) {
            if (auto ok = step_world(*world, frame_dt_s); !ok) return fail("soak: " + ok.error().message);
            const Garment& g = first_garment(*world);
            if (has_nonfinite(*world)) ++frames_left_nonfinite;
            const Entity anchor = g.body.colliders.at(static_cast<std::size_t>(g.body.anchor));
            const Vec3 hip = world->registry.get<EllipsoidCollider>(anchor).world.translation();
            row.farthest_from_hip_m =
                std::max(row.farthest_from_hip_m, static_cast<double>((g.state.x.colwise() - hip).colwise().norm().maxCoeff()));
            row.max_penetration_m = std::max(row.max_penetration_m, static_cast<double>(g.counters.max_penetration_m));
            row.max_strain = std::max(row.max_strain, static_cast<double>(measure_garment(world->registry, g).strain_max));
            const double e = kinetic_energy(g);
            energy_sum += e;
            row.peak_energy_J = std::max(row.peak_energy_J, e);
        }
        row.wall_s = elapsed_ms(start) * 1e-3;
        row.mean_energy_J = energy_sum / frames_per_minute;
        const Garment& g = first_garment(*world);
        row.nonfinite = g.counters.non_finite_values - nonfinite_seen;
        row.resets = g.counters.resets - resets_seen;
        row.teleports = world->teleports->teleports - teleports_seen;
        nonfinite_seen = g.counters.non_finite_values;
        resets_seen = g.counters.resets;
        teleports_seen = world->teleports->teleports;
        minutes.push_back(row);
        std::fprintf(stderr, "drape bench soak: minute %d/%d: farthest %.3f m, strain %.1f %%, energy %.4f J (%.1f s)\n", m,
                     *minutes_total, row.farthest_from_hip_m, 100 * row.max_strain, row.mean_energy_J, row.wall_s);
    }
    const double total_wall_s = elapsed_ms(start_all) * 1e-3;

    // Drift: the last tenth of the run against the first tenth (after the first minute, which
    // includes the garment settling from its rest shape).
    const std::size_t n = minutes.size();
    const std::size_t window = std::max<std::size_t>(1, n / 10);
    const std::size_t early_first = n > window + 1 ? 1 : 0;
    const std::size_t late_first = n - window;
    auto energy = [](const Minute& m) { return m.mean_energy_J; };
    auto strain = [](const Minute& m) { return m.max_strain; };
    auto farthest = [](const Minute& m) { return m.farthest_from_hip_m; };
    const double early_energy = mean_over(minutes, early_first, early_first + window, energy);
    const double late_energy = mean_over(minutes, late_first, n, energy);
    const double early_strain = mean_over(minutes, early_first, early_first + window, strain);
    const double late_strain = mean_over(minutes, late_first, n, strain);
    const double early_far = mean_over(minutes, early_first, early_first + window, farthest);
    const double late_far = mean_over(minutes, late_first, n, farthest);
    double worst_far = 0, worst_strain = 0, worst_pen = 0;
    std::uint64_t nonfinite = 0, resets = 0, teleports = 0;
    for (const auto& m : minutes) {
        worst_far = std::max(worst_far, m.farthest_from_hip_m);
        worst_strain = std::max(worst_strain, m.max_strain);
        worst_pen = std::max(worst_pen, m.max_penetration_m);
        nonfinite += m.nonfinite;
        resets += m.resets;
        teleports += m.teleports;
    }
    const double energy_ratio = early_energy > 0 ? late_energy / early_energy : NAN;

    nlohmann::json json;
    json["simulated_minutes"] = n;
    json["frame_dt_s"] = frame_dt_s;
    json["particles"] = particles;
    json["threads"] = options.threads;
    json["wall_s"] = total_wall_s;
    json["minutes"] = nlohmann::json::array();
    for (const auto& m : minutes)
        json["minutes"].push_back({{"minute", m.minute},
                                   {"farthest_from_hip_m", m.farthest_from_hip_m},
                                   {"max_penetration_m", m.max_penetration_m},
                                   {"max_strain", m.max_strain},
                                   {"mean_energy_J", m.mean_energy_J},
                                   {"peak_energy_J", m.peak_energy_J},
                                   {"nonfinite", m.nonfinite},
                                   {"resets", m.resets},
                                   {"teleports", m.teleports},
                                   {"wall_s", m.wall_s}});
    json["drift"] = {{"window_minutes", window},
                     {"energy_early_J", early_energy},
                     {"energy_late_J", late_energy},
                     {"energy_late_over_early", energy_ratio},
                     {"strain_early", early_strain},
                     {"strain_late", late_strain},
                     {"farthest_early_m", early_far},
                     {"farthest_late_m", late_far},
                     {"frames_ending_nonfinite", frames_left_nonfinite}};

    Report report("Soak: an hour of walking (`soak`)", options, machine);
    report.paragraph(
        "The sample scene (the default avatar walking in place in the default skirt, " + std::to_string(particles) +
        " particles, simplified model, candidate lists, automatic substeps) runs headless for " + std::to_string(n) +
        " simulated minutes at fixed 1/60 s frames (" + std::to_string(n * static_cast<std::size_t>(frames_per_minute)) +
        " frames, " + fixed(total_wall_s, 1) + " s of wall time). Every minute reports the farthest particle from the "
        "hip ellipsoid's centre, the deepest penetration the collision system found before its response, the worst "
        "warp/weft spring strain after the strain limit (the cloth's own counter, as in `drape play --stats`), the garment's kinetic energy (mean and peak over the "
        "minute's frames), and the non-finite values, resets and teleports counted that minute. Drift compares the "
        "last " + std::to_string(window) + " minute(s) with the first " + std::to_string(window) +
        " after minute 1 (which holds the settling from the rest shape).");
    report.heading("Drift");
    report.table({"quantity", "early", "late", "late / early"},
                 {{"kinetic energy, mean (J)", fixed(early_energy, 5), fixed(late_energy, 5), fixed(energy_ratio, 3)},
                  {"max strain (%)", fixed(100 * early_strain, 2), fixed(100 * late_strain, 2),
                   fixed(early_strain > 0 ? late_strain / early_strain : NAN, 3)},
                  {"farthest particle from hip (m)", fixed(early_far, 3), fixed(late_far, 3),
                   fixed(early_far > 0 ? late_far / early_far : NAN, 3)}});
    report.paragraph("Over the whole run: farthest particle " + fixed(worst_far, 3) + " m from the hip, deepest " +
                     "penetration " + fixed(1000 * worst_pen, 1) + " mm, worst strain " + fixed(100 * worst_strain, 2) +
                     " %, " + std::to_string(nonfinite) + " non-finite values, " + std::to_string(resets) + " resets, " +
                     std::to_string(teleports) + " teleports, " + std::to_string(frames_left_nonfinite) +
                     " frames ending with a non-finite value.");
    report.targets({upper_bound_target("late / early kinetic energy", energy_ratio, 1.5, "x", 3),
                    upper_bound_target("farthest particle from the hip", worst_far, 1.0, "m", 3),
                    upper_bound_target("non-finite values", static_cast<double>(nonfinite), 0, "", 0),
                    upper_bound_target("resets", static_cast<double>(resets), 0, "", 0)});

    PlotData data{"minutes", {}};
    for (const auto& m : minutes)
        data.rows.push_back({static_cast<double>(m.minute), 1000 * m.mean_energy_J, 1000 * m.peak_energy_J,
                             100 * m.max_strain, 100 * m.farthest_from_hip_m, 1000 * m.max_penetration_m});
    const std::string script =
        "set multiplot layout 2,1 title 'Soak: the sample scene walking, per simulated minute'\n"
        "set grid\nset key outside right\nset xlabel 'simulated minute'\n"
        "set ylabel 'kinetic energy (mJ)'\n"
        "plot $minutes using 1:2 with linespoints pt 7 ps 0.5 lw 2 lc rgb '#3060c0' title 'mean', "
        "$minutes using 1:3 with lines lw 1 lc rgb '#90a0d0' title 'peak'\n"
        "set ylabel 'strain (%), distance (cm), penetration (mm)'\n"
        "plot $minutes using 1:4 with linespoints pt 7 ps 0.5 lw 2 lc rgb '#c03020' title 'max strain (%)', "
        "$minutes using 1:5 with linespoints pt 5 ps 0.5 lw 2 lc rgb '#30a050' title 'farthest from hip (cm)', "
        "$minutes using 1:6 with linespoints pt 9 ps 0.5 lw 2 lc rgb '#202020' title 'max penetration (mm)'\n"
        "unset multiplot\n";
    if (auto ok = plot(options.out_dir, "soak.png", {data}, script, 1000, 760); ok)
        report.image("soak.png", "Energy, strain, distance and penetration per simulated minute");
    else
        report.missing_plot(ok.error().message);

    report.heading("Per minute");
    std::vector<std::vector<std::string>> rows;
    for (const auto& m : minutes)
        rows.push_back({std::to_string(m.minute), fixed(m.farthest_from_hip_m, 3), fixed(1000 * m.max_penetration_m, 1),
                        fixed(100 * m.max_strain, 2), fixed(1000 * m.mean_energy_J, 3), fixed(1000 * m.peak_energy_J, 3),
                        std::to_string(m.nonfinite), std::to_string(m.resets), std::to_string(m.teleports),
                        fixed(m.wall_s, 1)});
    report.table({"minute", "farthest from hip (m)", "max penetration (mm)", "max strain (%)", "mean energy (mJ)",
                  "peak energy (mJ)", "non-finite", "resets", "teleports", "wall (s)"},
                 rows);

    return finish(report, options, json);
}

}  // namespace drape::bench
