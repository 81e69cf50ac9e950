// `drape bench peers`: Bullet's soft-body cloth next to Drape's on the same skirt.
//
// One run: the default avatar walks in place wearing the default skirt (Drape's shipped
// configuration: simplified model, candidate lists, automatic substeps). A Bullet btSoftBody
// is built from the skirt as placed at the start (before either engine steps): the same
// particles and masses, one link per spring of the fabric with the fabric's rest length
// (SpringPhase::rest_m), in one of two constraint sets, each reported under its own label:
//   structural          the full grid's warp and weft springs (both layers), no bending links;
//   structural + bend   those and the fabric's bend springs (every second particle).
// Every frame Drape ticks first (its garment work is read from the frame profiler); then
// Bullet gets the same ellipsoids as kinematic bodies and the same pinned particles, moved to
// where Drape's pins are, and steps the same 1/60 s (timed around its step). Both alternate
// frame by frame, so both see the same machine load.
// Measured the same way for both, outside the timed work: penetration before the response
// (Drape: the deepest contact its collision rounds found before pushing out; Bullet: the
// deepest free node inside an ellipsoid after its prediction, before its solve) and after
// the frame, and strain after the frame, both by systems/cloth/garment_quality.hpp's
// measure_garment on the same spring list (structural springs with a free end).
// Bullet's configuration is chosen per constraint set from a sweep by a rule that reads
// Bullet's own figures only (select_bullet_configuration).
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "bench/bullet_cloth.hpp"
#include "bench/probe.hpp"
#include "bench/report.hpp"
#include "bench/stability_bench.hpp"
#include "bench/world.hpp"
#include "drape/systems/cloth/garment_quality.hpp"

#include <LinearMath/btScalar.h>

namespace drape::bench {

namespace {

constexpr double frame_dt_s = 1.0 / 60.0;
constexpr int settle_frames = 30;   ///< Not measured: the skirt drops from its rest shape.
constexpr int measured_frames = 600;
constexpr int sweep_frames = 300;   ///< Per Bullet configuration of the sweep.
const BulletSelectionRule selection_rule{};
/// A Bullet node farther than this times its line's rest length from its pin has blown up
/// (stability_bench.hpp's reach test).
constexpr double blown_up_reach = 2.0;

enum class Links { structural, structural_bend };
const char* links_name(Links l) { return l == Links::structural ? "structural" : "structural_bend"; }
const char* links_label(Links l) {
    return l == Links::structural ? "structural springs only" : "structural + bend springs";
}

/// Bullet's defaults, apart from what the cloth cannot run without.
BulletTuning bullet_defaults() {
    BulletTuning t;
    t.substeps = 1;
    t.position_iterations = 1;
    t.drift_iterations = 0;
    t.damping = 0;
    t.kinetic_hardness = 0.1f;
    t.sdf_voxel_m = 0.25f;
    t.margin_m = 0.0625f;   // 0.25 x the default SDF cell, as btSoftBodyHelpers leaves it.
    return t;
}

/// Contact and damping settings that keep Bullet's cloth together on a walking body; the
/// sweep varies internal steps and iterations on top of them.
BulletTuning tuned_contacts() {
    BulletTuning t;
    t.substeps = 2;
    t.position_iterations = 10;
    t.damping = 0.1f;
    t.kinetic_hardness = 1.0f;
    t.sdf_voxel_m = 0.05f;
    t.margin_m = 0.01f;
    return t;
}

/// The Bullet cloth of a garment as placed: its particles, masses, pins and springs with the
/// fabric's rest lengths.
ClothSpec cloth_spec(const Garment& g, Links links) {
    ClothSpec spec;
    spec.x = g.state.x;
    const StructuralSprings structural = structural_springs(*g.fabric);
    spec.springs = structural.springs;
    spec.rest_m = structural.rest_m;
    if (links == Links::structural_bend) {
        const SpringPhase& bend = g.fabric->bend;
        for (std::size_t i = 0; i < bend.size(); ++i) {
            spec.springs.push_back({bend.a[i], bend.b[i]});
            spec.rest_m.push_back(bend.rest_m[i]);
        }
    }
    spec.pinned = pinned_particles(g);
    spec.masses_kg.resize(static_cast<std::size_t>(g.state.inv_mass.size()));
    for (Eigen::Index i = 0; i < g.state.inv_mass.size(); ++i)
        spec.masses_kg[static_cast<std::size_t>(i)] = g.state.inv_mass[i] > 0 ? 1 / g.state.inv_mass[i] : Real(1);
    return spec;
}

/// One engine over a run.
struct EngineRun {
    std::vector<double> frame_ms;
    double penetration_before_m = 0, penetration_after_m = 0, strain_max = 0;
    StrainHistogram strain;
    [[nodiscard]] double strain_p99() const { return strain.samples() ? static_cast<double>(strain.percentile(0.99)) : NAN; }
};

struct Run {
    EngineRun drape, bullet;
    bool bullet_blew_up = false;
    int blew_up_frame = -1;
    std::size_t links = 0;
    double rest_gap_m = 0;   ///< Largest |Bullet's link rest length - the fabric's| after the run.
    std::size_t particles = 0;
};

/// One alternating run of `frames` measured frames after the settling ones.
Result<Run> alternate(Links links, const BulletTuning& tuning, int frames, bool stop_when_blown_up) {
    WorldSpec spec;
    auto world = build_bench_world(spec);
    if (!world) return fail(world.error().message);

    const Garment& g0 = first_garment(*world);
    const ClothSpec cloth = cloth_spec(g0, links);
    auto bullet = BulletCloth::create(cloth, collider_worlds(world->registry, g0), tuning);
    if (!bullet) return fail(bullet.error().message);
    const PinReach reach = pin_reach(static_cast<std::size_t>(g0.state.x.cols()), structural_springs(*g0.fabric), cloth.pinned);
    Garment bullet_view = g0;   // Bullet's positions in a Drape garment, for measure_garment
    bullet_view.state.v.setZero();

    Run run;
    run.links = cloth.springs.size();
    run.particles = static_cast<std::size_t>(g0.state.x.cols());
    Matrix3X pinned_x(3, static_cast<Eigen::Index>(cloth.pinned.size()));
    for (int frame = 0; frame < settle_frames + frames; ++frame) {
        const ClothSystemTime before = cloth_system_totals(world->scheduler);
        if (auto ok = step_world(*world, frame_dt_s); !ok) return fail(ok.error().message);
        const ClothSystemTime after = cloth_system_totals(world->scheduler);
        const Garment& g = first_garment(*world);
        const auto ellipsoids = collider_worlds(world->registry, g);
        for (std::size_t k = 0; k < cloth.pinned.size(); ++k)
            pinned_x.col(static_cast<Eigen::Index>(k)) = g.state.x.col(cloth.pinned[k]);

        bool bullet_measured = false;
        if (!run.bullet_blew_up) {
            const auto start = now_ns();
            bullet->step(pinned_x, ellipsoids, frame_dt_s);
            const double ms = elapsed_ms(start) - bullet->last_frame().probe_ms;
            bullet_view.state.x = bullet->positions();
            if (!bullet_view.state.x.allFinite() || !(worst_reach_ratio(bullet_view.state.x, reach) <= blown_up_reach)) {
                run.bullet_blew_up = true;
                run.blew_up_frame = frame;
                if (stop_when_blown_up) break;
            } else if (frame >= settle_frames) {
                run.bullet.frame_ms.push_back(ms);
                bullet_measured = true;
            }
        }
        if (frame < settle_frames) continue;
        run.drape.frame_ms.push_back(after.garment_ms - before.garment_ms);
        run.drape.penetration_before_m = std::max(run.drape.penetration_before_m, static_cast<double>(g.counters.max_penetration_m));
        const GarmentQuality dq = measure_garment(world->registry, g, &run.drape.strain);
        run.drape.penetration_after_m = std::max(run.drape.penetration_after_m, static_cast<double>(dq.penetration_m));
        run.drape.strain_max = std::max(run.drape.strain_max, static_cast<double>(dq.strain_max));
        if (bullet_measured) {
            run.bullet.penetration_before_m = std::max(run.bullet.penetration_before_m, bullet->last_frame().penetration_before_m);
            const GarmentQuality bq = measure_garment(world->registry, bullet_view, &run.bullet.strain);
            run.bullet.penetration_after_m = std::max(run.bullet.penetration_after_m, static_cast<double>(bq.penetration_m));
            run.bullet.strain_max = std::max(run.bullet.strain_max, static_cast<double>(bq.strain_max));
        }
    }
    const std::vector<Real> held = bullet->link_rest_lengths();
    for (std::size_t i = 0; i < held.size() && i < cloth.rest_m.size(); ++i)
        run.rest_gap_m = std::max(run.rest_gap_m, static_cast<double>(std::abs(held[i] - cloth.rest_m[i])));
    return run;
}

/// What one Bullet configuration did over a sweep run.
struct Outcome {
    BulletTuning tuning;
    std::string label;
    bool ran = false;          ///< False: the run could not start (message in `error`).
    bool crashed = false;      ///< Bullet died with a signal.
    int signal = 0;
    bool blew_up = false;      ///< A node went non-finite or beyond twice its line's rest length from its pin.
    int blew_up_frame = -1;
    double ms = NAN, strain_p99 = NAN, strain_max = NAN, penetration_after_m = NAN, penetration_before_m = NAN;
    std::string error;
    [[nodiscard]] bool usable() const { return ran && !crashed && !blew_up; }
};

/// Runs one Bullet configuration in a child process: an exploding soft body can crash
/// Bullet (its sparse SDF indexes cells with non-finite coordinates), and that must not
/// end the benchmark.
Outcome run_isolated(Links links, const BulletTuning& tuning, const std::string& label, int frames) {
    Outcome out;
    out.tuning = tuning;
    out.label = label;
    int pipe_fd[2];
    if (::pipe(pipe_fd) != 0) {
        out.error = "no pipe";
        return out;
    }
    const pid_t child = ::fork();
    if (child < 0) {
        out.error = "fork failed";
        return out;
    }
    if (child == 0) {
        ::close(pipe_fd[0]);
        ::alarm(600);   // A run that hangs ends as a crash (SIGALRM) rather than stalling the benchmark.
        char buffer[1024];
        auto run = alternate(links, tuning, frames, true);
        if (!run)
            std::snprintf(buffer, sizeof buffer, "E %s", run.error().message.c_str());
        else
            std::snprintf(buffer, sizeof buffer, "R %d %d %.9g %.9g %.9g %.9g %.9g", run->bullet_blew_up ? 1 : 0,
                          run->blew_up_frame, median(run->bullet.frame_ms), run->bullet.strain_p99(), run->bullet.strain_max,
                          run->bullet.penetration_after_m, run->bullet.penetration_before_m);
        [[maybe_unused]] auto written = ::write(pipe_fd[1], buffer, std::strlen(buffer));
        ::close(pipe_fd[1]);
        ::_exit(0);
    }
    ::close(pipe_fd[1]);
    std::string message;
    char buffer[512];
    for (ssize_t n; (n = ::read(pipe_fd[0], buffer, sizeof buffer)) > 0;) message.append(buffer, static_cast<std::size_t>(n));
    ::close(pipe_fd[0]);
    int status = 0;
    ::waitpid(child, &status, 0);
    if (WIFSIGNALED(status)) {
        out.ran = true;
        out.crashed = true;
        out.signal = WTERMSIG(status);
        return out;
    }
    if (message.rfind("E ", 0) == 0) {
        out.error = message.substr(2);
        return out;
    }
    int blew_up = 0;
    if (std::sscanf(message.c_str(), "R %d %d %lf %lf %lf %lf %lf", &blew_up, &out.blew_up_frame, &out.ms, &out.strain_p99,
                    &out.strain_max, &out.penetration_after_m, &out.penetration_before_m) != 7) {
        out.error = "no result from the child process";
        return out;
    }
    out.ran = true;
    out.blew_up = blew_up != 0;
    return out;
}

std::string describe(const Outcome& o) {
    if (!o.ran) return "could not run: " + o.error;
    if (o.crashed)
        return std::string("crashed inside Bullet (signal ") + std::to_string(o.signal) + ", " + strsignal(o.signal) +
               ") after the cloth blew up";
    if (o.blew_up)
        return "blew up at frame " + std::to_string(o.blew_up_frame) + " (" + fixed(o.blew_up_frame * frame_dt_s, 2) +
               " s): a node went non-finite or beyond " + fixed(blown_up_reach, 0) + "x its line's rest length from its pin";
    return "ran";
}

std::string tuning_text(const BulletTuning& t) {
    return std::to_string(t.substeps) + " internal steps, piterations " + std::to_string(t.position_iterations) +
           ", kDP " + fixed(t.damping, 2) + ", kKHR " + fixed(t.kinetic_hardness, 2) + ", SDF cell " +
           fixed(1000 * t.sdf_voxel_m, 0) + " mm, margin " + fixed(1000 * t.margin_m, 1) + " mm";
}

nlohmann::json tuning_json(const BulletTuning& t) {
    return {{"internal_steps", t.substeps}, {"position_iterations", t.position_iterations}, {"kDP", t.damping},
            {"kKHR", t.kinetic_hardness},   {"sdf_cell_m", t.sdf_voxel_m},               {"margin_m", t.margin_m}};
}

/// One constraint set: its sweep, the configuration chosen, and the comparison runs.
struct VariantResult {
    Links links = Links::structural;
    std::vector<Outcome> sweep;
    BulletSelection selection;
    BulletTuning chosen;
    std::vector<double> drape_ms, bullet_ms;   ///< Per run: the median frame.
    EngineRun drape, bullet;                   ///< Worst quality over the runs (strain histograms of the first run).
    double drape_p99 = 0, bullet_p99 = 0;      ///< Worst over the runs.
    std::string note;
    std::size_t links_count = 0;
    double rest_gap_m = 0;
    [[nodiscard]] double ratio() const { return median(drape_ms) / median(bullet_ms); }
};

void worst_of(EngineRun& into, const EngineRun& run) {
    into.penetration_before_m = std::max(into.penetration_before_m, run.penetration_before_m);
    into.penetration_after_m = std::max(into.penetration_after_m, run.penetration_after_m);
    into.strain_max = std::max(into.strain_max, run.strain_max);
}

nlohmann::json engine_json(const std::string& engine, const std::string& variant, double ms, const EngineRun& e, double p99) {
    return {{"engine", engine},
            {"variant", variant},
            {"ms_per_frame", ms},
            {"penetration_before_max_m", e.penetration_before_m},
            {"penetration_after_max_m", e.penetration_after_m},
            {"strain_max", e.strain_max},
            {"strain_p99", p99}};
}

}  // namespace

Result<void> run_peers(const BenchOptions& options) {
    const Machine machine = describe_machine();
    std::vector<VariantResult> variants;
    std::size_t particles = 0;
    for (Links links : {Links::structural, Links::structural_bend}) {
        VariantResult v;
        v.links = links;
        std::fprintf(stderr, "drape bench peers: Bullet with %s: sweep\n", links_label(links));
        // 1. Bullet's defaults and a sweep of solver effort, each isolated in a child process.
        v.sweep.push_back(run_isolated(links, bullet_defaults(), "Bullet defaults", sweep_frames));
        for (auto [substeps, iterations] : {std::pair{1, 4}, {1, 10}, {2, 10}, {4, 10}, {4, 20}, {8, 20}}) {
            BulletTuning t = tuned_contacts();
            t.substeps = substeps;
            t.position_iterations = iterations;
            v.sweep.push_back(run_isolated(links, t, "tuned contacts", sweep_frames));
        }
        std::vector<BulletCandidate> candidates;
        for (const Outcome& o : v.sweep) candidates.push_back({o.usable(), o.ms, o.strain_p99, o.penetration_after_m});
        v.selection = select_bullet_configuration(candidates, selection_rule);
        if (v.selection.index < 0)
            return fail(std::string("peers: no Bullet configuration ran without blowing up with ") + links_label(links) + " (" +
                        describe(v.sweep.front()) + ")");
        v.chosen = v.sweep[static_cast<std::size_t>(v.selection.index)].tuning;

        // 2. The comparison: Drape and the chosen Bullet configuration alternating, `runs` times.
        std::fprintf(stderr, "drape bench peers: Bullet with %s: comparison\n", links_label(links));
        for (int r = 0; r < options.runs; ++r) {
            auto run = alternate(links, v.chosen, measured_frames, false);
            if (!run) return fail("peers: " + run.error().message);
            v.drape_ms.push_back(median(run->drape.frame_ms));
            v.bullet_ms.push_back(median(run->bullet.frame_ms));
            worst_of(v.drape, run->drape);
            worst_of(v.bullet, run->bullet);
            v.drape_p99 = std::max(v.drape_p99, run->drape.strain_p99());
            v.bullet_p99 = std::max(v.bullet_p99, run->bullet.strain_p99());
            v.links_count = run->links;
            v.rest_gap_m = std::max(v.rest_gap_m, run->rest_gap_m);
            particles = run->particles;
            if (run->bullet_blew_up)
                v.note = "Bullet blew up at frame " + std::to_string(run->blew_up_frame) + " of a run; its figures stop there.";
        }
        variants.push_back(std::move(v));
    }
    const int version = btGetVersion();
    const std::string bullet_version = std::to_string(version / 100) + "." + std::to_string(version % 100);
    const VariantResult& primary = variants.front();

    nlohmann::json json;
    json["particles"] = particles;
    json["rows"] = nlohmann::json::array();
    json["rows"].push_back(engine_json("Drape", "simplified + candidate lists, automatic substeps", median(primary.drape_ms),
                                       primary.drape, primary.drape_p99));
    for (const VariantResult& v : variants) {
        auto row = engine_json("Bullet", links_name(v.links), median(v.bullet_ms), v.bullet, v.bullet_p99);
        row["links"] = v.links_count;
        row["tuning"] = tuning_json(v.chosen);
        row["meets_selection_rule"] = v.selection.qualified;
        row["drape_ms_same_runs"] = median(v.drape_ms);
        row["ratio_drape_over_bullet"] = v.ratio();
        row["rest_length_gap_m"] = v.rest_gap_m;
        json["rows"].push_back(row);
    }
    json["ratio_drape_over_bullet"] = primary.ratio();
    json["selection_rule"] = {{"strain_p99_max", selection_rule.strain_p99_max},
                              {"penetration_after_max_m", selection_rule.penetration_after_max_m},
                              {"else", "least strain p99"}};
    json["sweep"] = nlohmann::json::object();
    for (const VariantResult& v : variants) {
        auto& list = json["sweep"][links_name(v.links)] = nlohmann::json::array();
        for (const Outcome& o : v.sweep)
            list.push_back({{"label", o.label}, {"tuning", tuning_json(o.tuning)}, {"outcome", describe(o)},
                            {"ms_per_frame", o.usable() ? nlohmann::json(o.ms) : nlohmann::json()},
                            {"strain_p99", o.usable() ? nlohmann::json(o.strain_p99) : nlohmann::json()},
                            {"penetration_after_max_m", o.usable() ? nlohmann::json(o.penetration_after_m) : nlohmann::json()},
                            {"penetration_before_max_m", o.usable() ? nlohmann::json(o.penetration_before_m) : nlohmann::json()}});
    }

    Report report("Drape and Bullet side by side (`peers`)", options, machine);
    report.paragraph(
        "The default avatar walks in place at 60 fps wearing the default skirt (" + std::to_string(particles) +
        " particles). Drape runs its shipped configuration: simplified model, candidate-list collision, automatic "
        "substeps. Bullet " + bullet_version + " (Debian's libbullet-dev) runs a btSoftBody built from the skirt as "
        "placed at the start, before either engine steps: the same particles with Drape's masses, the same pinned "
        "particles (moved kinematically every frame to where Drape's pins are on the skin), and one link per spring "
        "of the fabric **with the fabric's rest length** (Bullet would take the distance at creation; the benchmark "
        "writes the fabric's after Bullet's own constant update, and checks after each run that Bullet still holds "
        "them: largest difference " + fixed(1000 * std::max(variants[0].rest_gap_m, variants[1].rest_gap_m), 4) +
        " mm). Two constraint sets, each reported under its own label: **structural** (" +
        std::to_string(variants[0].links_count) + " links: warp of both layers and weft, the springs strain is "
        "measured on; no bending links) and **structural + bend** (" + std::to_string(variants[1].links_count) +
        " links: those and the fabric's bend springs, every second particle along warp and weft). The ellipsoids are "
        "kinematic rigid bodies (a one-sphere btMultiSphereShape with local scaling); SDF_RS soft-rigid collision.");
    report.paragraph(
        "Both step 1/60 s per frame and alternate frame by frame in one process, so both see the same machine load. "
        "Drape's time is its garment work (every simulation-phase system, from the frame profiler); Bullet's is its "
        "stepSimulation plus moving the pins, less the time of the before-response probe below. Measured the same way "
        "for both: **penetration before the response**, the deepest free particle inside an ellipsoid before the "
        "engine answers the contact (Drape: what its collision rounds detect before pushing out, the garment's "
        "counter; Bullet: its nodes after its prediction, before its link and contact solve, from the world's "
        "internal tick callback in every internal step); **penetration after the frame** and **strain after the "
        "frame** by measure_garment (systems/cloth/garment_quality.hpp), the same function on the same spring list "
        "(structural springs with a free end) for both. " + std::to_string(settle_frames) + " settling frames, then " +
        std::to_string(measured_frames) + " measured frames per run; ms are the median frame of each run, then the "
        "median over " + std::to_string(options.runs) + " runs; penetration and strain are the worst over the runs "
        "(strain p99 over each run's springs and frames).");

    report.heading("Results");
    std::vector<std::vector<std::string>> rows;
    rows.push_back({"Drape (simplified + candidate lists)", "-", fixed(median(primary.drape_ms), 3), "-",
                    fixed(1000 * primary.drape.penetration_before_m, 2), fixed(1000 * primary.drape.penetration_after_m, 2),
                    fixed(100 * primary.drape.strain_max, 1), fixed(100 * primary.drape_p99, 1)});
    for (const VariantResult& v : variants)
        rows.push_back({std::string("Bullet btSoftBody, ") + links_label(v.links), tuning_text(v.chosen),
                        fixed(median(v.bullet_ms), 3), fixed(v.ratio(), 3), fixed(1000 * v.bullet.penetration_before_m, 2),
                        fixed(1000 * v.bullet.penetration_after_m, 2), fixed(100 * v.bullet.strain_max, 1),
                        fixed(100 * v.bullet_p99, 1)});
    report.table({"engine", "configuration", "ms per frame", "Drape / Bullet time (same runs)", "penetration before response (mm)",
                  "penetration after frame (mm)", "strain max (%)", "strain p99 (%)"},
                 rows);
    std::string notes;
    for (const VariantResult& v : variants) {
        notes += std::string("With ") + links_label(v.links) + ": Drape " + fixed(median(v.drape_ms), 3) + " ms in the same runs; "
                 "Bullet's configuration " + (v.selection.qualified ? "meets" : "**does not meet**") + " the selection rule" +
                 (v.selection.qualified ? "" : " (none in the sweep does; the one with the least strain p99 is used)") + ". ";
        if (!v.note.empty()) notes += v.note + " ";
    }
    report.paragraph(notes);

    report.heading("Targets");
    report.paragraph("Drape at least 10x cheaper than Bullet, measured in the same runs.");
    report.targets({upper_bound_target("Drape time / Bullet time, structural springs only", primary.ratio(), 0.1, "", 3),
                    upper_bound_target("Drape time / Bullet time, structural + bend springs", variants[1].ratio(), 0.1, "", 3)});

    report.heading("Bullet's configuration");
    report.paragraph(
        "Each configuration below ran once for " + std::to_string(settle_frames + sweep_frames) + " frames against "
        "the same walking avatar, in a child process (a soft body that blows up can crash Bullet); a node beyond " +
        fixed(blown_up_reach, 0) + "x its line's rest length from its pin ends the run as blown up. \"Bullet "
        "defaults\": 1 internal step per frame, 1 position iteration, kDP 0, kKHR 0.1, the default 0.25 m sparse-SDF "
        "cell and its 62.5 mm margin. \"Tuned contacts\": kDP 0.1 damping, kKHR 1 (contacts with the kinematic "
        "ellipsoids as hard as rigid ones), a 50 mm SDF cell (the default cell is larger than a thigh), 10 mm margin. "
        "**Selection rule**, on Bullet's own figures only: the cheapest configuration that did not blow up whose "
        "strain p99 after the frame is at most " + fixed(100 * selection_rule.strain_p99_max, 0) + " % and whose "
        "penetration after the frame stays within " + fixed(1000 * selection_rule.penetration_after_max_m, 0) +
        " mm; when none qualifies, the one with the least strain p99.");
    for (const VariantResult& v : variants) {
        std::vector<std::vector<std::string>> sweep_rows;
        for (std::size_t i = 0; i < v.sweep.size(); ++i) {
            const Outcome& o = v.sweep[i];
            const bool usable = o.usable();
            sweep_rows.push_back({o.label, std::to_string(o.tuning.substeps), std::to_string(o.tuning.position_iterations),
                                  usable ? fixed(o.ms, 3) : "-", usable ? fixed(100 * o.strain_p99, 1) : "-",
                                  usable ? fixed(100 * o.strain_max, 1) : "-", usable ? fixed(1000 * o.penetration_before_m, 2) : "-",
                                  usable ? fixed(1000 * o.penetration_after_m, 2) : "-",
                                  describe(o) + (static_cast<int>(i) == v.selection.index ? " (**used above**)" : "")});
        }
        report.paragraph(std::string("Bullet with ") + links_label(v.links) + ":");
        report.table({"configuration", "internal steps", "iterations", "ms per frame", "strain p99 (%)", "strain max (%)",
                      "penetration before (mm)", "penetration after (mm)", "outcome"},
                     sweep_rows);
    }

    std::vector<PlotData> data{
        {"ms", {{0, median(primary.drape_ms)}, {1, median(variants[0].bullet_ms)}, {2, median(variants[1].bullet_ms)}}},
        {"pen",
         {{0, 1000 * primary.drape.penetration_after_m}, {1, 1000 * variants[0].bullet.penetration_after_m},
          {2, 1000 * variants[1].bullet.penetration_after_m}}},
        {"strain", {{0, 100 * primary.drape_p99}, {1, 100 * variants[0].bullet_p99}, {2, 100 * variants[1].bullet_p99}}}};
    const std::string script =
        "set multiplot layout 1,3 title 'Drape vs Bullet soft body, " + std::to_string(particles) +
        "-particle skirt, walking avatar'\n"
        "set style fill solid 0.7\nset boxwidth 0.6\nset xtics ('Drape' 0, 'Bullet structural' 1, 'Bullet + bend' 2)\nset xrange [-0.6:2.6]\n"
        "set yrange [0:*]\nset grid ytics\nunset key\n"
        "set title 'ms per frame'\nplot $ms using 1:2 with boxes lc rgb '#3060c0'\n"
        "set title 'max penetration after frame (mm)'\nplot $pen using 1:2 with boxes lc rgb '#c04030'\n"
        "set title 'strain p99 after frame (%)'\nplot $strain using 1:2 with boxes lc rgb '#30a050'\n"
        "unset multiplot\n";
    report.plot("peers.png", "Drape and Bullet: time, penetration, strain", data, script, 1200, 420);

    return finish(report, options, json);
}

}  // namespace drape::bench
