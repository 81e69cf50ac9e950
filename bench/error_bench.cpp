// `drape bench error`: error against run time, and analytic references.
//
// Sweep: model x substeps x constraint rounds x collision on the walking default avatar with
// the default skirt, against a converged reference over short restarted horizons
// (bench/reference.hpp): the classic model (every spring) with brute-force collision (every
// test) at a substep count doubled until its own refinement moves it by less than 1 mm RMS.
// What remains of a configuration's distance from it is what each shortcut (fewer springs,
// fewer substeps, fewer rounds, candidate lists) costs. After every frame the garment's
// quality is measured as `drape play --stats` measures it (systems/cloth/garment_quality.hpp):
// strain of the structural springs with a free end, and free particles inside the body.
//
// Analytic references (no body): a mass on a spring (period and amplitude of the
// compliance-form spring against backward Euler, by step size) and a chain hanging between two pins
// (static sag against the catenary).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "bench/reference.hpp"
#include "bench/report.hpp"
#include "bench/world.hpp"
#include "drape/systems/cloth/garment_config.hpp"
#include "drape/systems/cloth/garment_quality.hpp"
#include "drape/systems/cloth_systems.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_step.hpp"

namespace drape::bench {

namespace {

constexpr double frame_dt_s = 1.0 / 60.0;
constexpr int reference_first_substeps = 16;
constexpr int reference_max_substeps = 256;
constexpr double reference_tolerance_m = 1e-3;

struct SweepRow {
    ClothModel model;
    int substeps;   ///< 0 = automatic.
    int iterations;
    CollisionMode collision;
    ClothIntegrator integrator = ClothIntegrator::shipped;
    double ms_per_frame = 0, rms_error_m = 0;
    double strain_max = 0, strain_p99 = 0, penetration_after_m = 0;
    double mean_substeps = 0;
};

const char* model_name(ClothModel m) { return m == ClothModel::simplified ? "simplified" : "classic"; }
const char* collision_name(CollisionMode c) { return c == CollisionMode::candidate_lists ? "lists" : "brute_force"; }

Result<World> sweep_world(ClothModel model, int substeps, int iterations, CollisionMode collision, int threads,
                          ClothIntegrator integrator = ClothIntegrator::shipped) {
    WorldSpec spec;
    spec.model = model;
    spec.integrator = integrator;
    spec.collision = collision;
    spec.substeps = substeps;
    spec.threads = threads;
    auto world = build_bench_world(spec);
    if (!world) return world;
    ClothMaterial material = first_garment(*world).config.material;
    material.iterations = iterations;
    if (auto ok = set_garment_material(world->registry, world->garments.at(0), material); !ok) return fail(ok.error().message);
    return world;
}

/// Distance from the reference over its horizons, with the time and after-frame quality of
/// every frame from the first horizon on.
Result<SweepRow> measure(SweepRow row, const HorizonPlan& plan, const ConvergedReference& reference, int threads) {
    auto world = sweep_world(row.model, row.substeps, row.iterations, row.collision, threads, row.integrator);
    if (!world) return fail(world.error().message);
    std::vector<double> frame_ms;
    StrainHistogram strains;
    double substeps = 0;
    auto states = run_horizons(*world, plan, &reference.states, [&](World& w, int frame, double garment_ms) {
        if (frame < plan.warmup_frames) return;
        const Garment& g = first_garment(w);
        const GarmentQuality q = measure_garment(w.registry, g, &strains);
        row.strain_max = std::max(row.strain_max, static_cast<double>(q.strain_max));
        row.penetration_after_m = std::max(row.penetration_after_m, static_cast<double>(q.penetration_m));
        frame_ms.push_back(garment_ms);
        substeps += g.counters.substeps;
    });
    if (!states) return fail(states.error().message);
    row.ms_per_frame = median(frame_ms);   // the median frame: robust to other work on the machine
    row.strain_p99 = strains.percentile(0.99);
    row.rms_error_m = horizon_rms_m(*states, reference.states);
    row.mean_substeps = frame_ms.empty() ? 0 : substeps / static_cast<double>(frame_ms.size());
    return row;
}

// --- Analytic references -------------------------------------------------------------

struct Solo {
    Registry registry;
    Scheduler scheduler;
    Entity garment;
};

/// A rectangle garment alone in a world with the cloth systems; `substeps` 0 = the rule.
Result<std::unique_ptr<Solo>> solo_cloth(Garment garment, double fixed_dt_s, int substeps) {
    SchedulerSettings settings;
    settings.fixed_dt_s = fixed_dt_s;
    auto scheduler = Scheduler::create(settings);
    if (!scheduler) return fail(scheduler.error().message);
    auto solo = std::make_unique<Solo>();
    solo->scheduler = std::move(*scheduler);
    ClothSolverSettings cloth;
    cloth.fixed_substeps = substeps;
    add_cloth_systems(solo->scheduler, cloth);
    solo->garment = solo->registry.create();
    solo->registry.emplace<Garment>(solo->garment, std::move(garment));
    return solo;
}

struct OscillatorRow {
    double steps_per_period, h_s, omega_h;
    double period_error, expected_period_error;     ///< Relative, measured and backward Euler's.
    double amplitude_drift, expected_amplitude_drift; ///< Period 19's amplitude / period 0's - 1.
    bool stable;
};

/// A mass on a spring standing on a pin; returns period and amplitude behaviour at step h.
/// The mass stands above the pin so that the spring oscillates shorter than its rest length:
/// hanging below, it would stretch past it, which the tethers (a particle no farther from its
/// pin than the rest length of the line between them, constraints.hpp) forbid.
Result<OscillatorRow> oscillator(double steps_per_period) {
    RectangleParams p;
    p.warp_lines = 2;                   // two identical lines side by side (the builder needs two)
    p.particles_per_line = 2;
    p.weft_stride = 1;
    p.width_m = 0.1f;
    p.length_m = 1;
    p.material.areal_density_kg_m2 = 4;  // 0.025 m^2 per particle: 0.1 kg
    p.material.stretch_N_m = 1600;        // k = 1600 x (0.025 + 0.025) / (2 x 1 m^2) = 40 N/m
    p.material.drag_N_s_m3 = 0;
    p.material.strain_limit = 10;       // the largest allowed: Provot must not hold the oscillator
    auto garment = make_rectangle(p);
    if (!garment) return fail("oscillator: " + garment.error().message);
    const auto& grid = garment->fabric->grid;
    for (std::size_t line = 0; line < 2; ++line) {   // row 1 of each line from below its pin to above it
        const std::uint32_t pin = grid[2 * line], mass = grid[2 * line + 1];
        garment->state.x.col(mass) = 2 * garment->state.x.col(pin) - garment->state.x.col(mass);
    }
    const std::uint32_t free = grid[1];   // line 0, row 1
    const double m = 1.0 / garment->state.inv_mass[free];
    const double k = 40;
    const double omega = std::sqrt(k / m);
    const double period = 2 * std::numbers::pi / omega;
    const double h = period / steps_per_period;
    const double amplitude = m * standard_gravity_m_s2 / k;
    const double y_eq = garment->state.x(1, free) - amplitude;
    auto solo = solo_cloth(std::move(*garment), h, 1);
    if (!solo) return fail("oscillator: " + solo.error().message);
    Solo& world = **solo;

    const int periods = 20;
    const int steps = static_cast<int>(std::ceil(periods * steps_per_period));
    std::vector<double> crossings;
    std::vector<double> amplitude_per_period(periods + 1, 0.0);
    double previous = world.registry.get<Garment>(world.garment).state.x(1, free) - y_eq;
    bool stable = true;
    for (int s = 1; s <= steps; ++s) {
        if (auto ok = world.scheduler.tick(world.registry, h); !ok) return fail(ok.error().message);
        const Garment& g = world.registry.get<Garment>(world.garment);
        const double d = g.state.x(1, free) - y_eq;
        if (!std::isfinite(d) || std::abs(d) > 20 * amplitude || g.counters.resets > 0) {
            stable = false;
            break;
        }
        const auto which = static_cast<std::size_t>(std::min(periods, static_cast<int>((s * h) / period)));
        amplitude_per_period[which] = std::max(amplitude_per_period[which], std::abs(d));
        // Crossings count while the swing is well above float noise (a damped swing dies out).
        const double swing = which == 0 ? amplitude : amplitude_per_period[which - 1];
        if (previous < 0 && d >= 0 && swing > 1e-3 * amplitude) crossings.push_back((s - 1 + (-previous) / (d - previous)) * h);
        previous = d;
    }
    OscillatorRow row{steps_per_period, h, omega * h, NAN, NAN, NAN, NAN, stable};
    // One linear spring in compliance form is backward Euler: each step turns the phase by
    // atan(omega h) and scales the amplitude by 1 / sqrt(1 + (omega h)^2).
    row.expected_period_error = omega * h / std::atan(omega * h) - 1;
    row.expected_amplitude_drift = std::pow(1 + omega * omega * h * h, -0.5 * (periods - 1) * steps_per_period) - 1;
    if (stable && crossings.size() >= 2)
        row.period_error = ((crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1)) / period - 1;
    if (stable && amplitude_per_period[0] > 0)
        row.amplitude_drift = amplitude_per_period[periods - 1] / amplitude_per_period[0] - 1;
    return row;
}

/// A sheet with no body: how its end after a frame and after a horizon moves when its substeps
/// double (the reference's convergence with the body's motion and contacts taken away).
struct SheetRow {
    int substeps;
    double one_frame_m, horizon_m;   ///< RMS distance to the run at twice the substeps.
};

Result<std::vector<SheetRow>> sheet_convergence(int horizon_frames) {
    RectangleParams p;
    p.model = ClothModel::classic;
    p.hanging = false;                 // a horizontal sheet pinned along one edge falls and swings
    auto garment = make_rectangle(p);
    if (!garment) return fail("sheet: " + garment.error().message);
    const Registry registry;
    auto run = [&](const Garment& from, int substeps, int frames) {
        Garment g = from;
        GarmentSolver solver;
        ClothSolverSettings settings;
        settings.fixed_substeps = substeps;
        for (int f = 0; f < frames; ++f) step_garment(registry, g, solver, frame_dt_s, settings);
        return g;
    };
    const Garment swinging = run(*garment, 16, 20);   // a third of a second into the swing
    auto distance = [](const Garment& a, const Garment& b) {
        return std::sqrt((a.state.x - b.state.x).cast<double>().colwise().squaredNorm().mean());
    };
    std::vector<SheetRow> rows;
    for (int n = 2; n <= 128; n *= 2)
        rows.push_back({n, distance(run(swinging, n, 1), run(swinging, 2 * n, 1)),
                        distance(run(swinging, n, horizon_frames), run(swinging, 2 * n, horizon_frames))});
    return rows;
}

struct ChainRow {
    int particles;
    double sag_m, catenary_sag_m, inextensible_sag_m, rms_shape_m, mean_strain;
};

double catenary_parameter(double span, double length) {
    // length = 2 a sinh(span / 2a): decreasing in a; bisection on a.
    double lo = 1e-4, hi = 1e4;
    for (int i = 0; i < 200; ++i) {
        const double a = std::sqrt(lo * hi);
        (2 * a * std::sinh(span / (2 * a)) > length ? lo : hi) = a;
    }
    return std::sqrt(lo * hi);
}

/// A chain of `particles` on 1 m of rest length, its ends pinned 0.8 m apart, settled.
Result<ChainRow> hanging_chain(int particles) {
    RectangleParams p;
    p.warp_lines = 2;                            // two chains 5 cm apart, joined by weft springs
    p.particles_per_line = particles;
    p.weft_stride = 1;
    p.width_m = 0.05f;
    p.length_m = 1;
    p.hanging = false;                           // rows along +Z
    p.origin = Vec3(0, 2, 0);
    p.material.areal_density_kg_m2 = 4;          // 0.05 m^2: 0.1 kg per chain
    p.material.stretch_N_m = 1000;               // the same chain stiffness EA for every particle count
    p.material.drag_N_s_m3 = 0.004f * 4 / 0.05f * static_cast<Real>(particles) / 40;
    auto garment = make_rectangle(p);
    if (!garment) return fail("chain: " + garment.error().message);
    const double span = 0.8;
    const auto n = static_cast<Eigen::Index>(particles);
    const auto& grid = garment->fabric->grid;
    auto at = [&](int line, Eigen::Index row) { return grid[static_cast<std::size_t>(line * n + row)]; };
    for (int line = 0; line < 2; ++line) {
        for (Eigen::Index i = 0; i < n; ++i)
            garment->state.x.col(at(line, i)) = Vec3(0.05f * static_cast<Real>(line), 2, static_cast<Real>(span * i / (n - 1)));
        const std::uint32_t end = at(line, n - 1);
        garment->state.inv_mass[end] = 0;
        PinBinding pin;
        pin.particle = end;
        pin.kind = PinKind::world;
        garment->state.pins.push_back(pin);
    }
    for (auto& b : garment->state.pins) b.local = garment->state.x.col(b.particle);
    auto solo = solo_cloth(std::move(*garment), 1.0 / 240.0, 0);
    if (!solo) return fail("chain: " + solo.error().message);
    Solo& world = **solo;
    for (int s = 0; s < 240 * 25; ++s)
        if (auto ok = world.scheduler.tick(world.registry, 1.0 / 240.0); !ok) return fail(ok.error().message);
    const Garment& g = world.registry.get<Garment>(world.garment);
    ChainRow row{particles, 0, 0, 0, 0, 0};
    double length = 0;
    for (Eigen::Index i = 0; i + 1 < n; ++i) length += (g.state.x.col(at(0, i + 1)) - g.state.x.col(at(0, i))).norm();
    row.mean_strain = length / 1.0 - 1;
    double lowest = 2.0;
    for (Eigen::Index i = 0; i < n; ++i) lowest = std::min(lowest, static_cast<double>(g.state.x(1, at(0, i))));
    row.sag_m = 2.0 - lowest;
    const double a = catenary_parameter(span, length);
    row.catenary_sag_m = a * (std::cosh(span / (2 * a)) - 1);
    const double a0 = catenary_parameter(span, 1.0);
    row.inextensible_sag_m = a0 * (std::cosh(span / (2 * a0)) - 1);
    double sum = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
        const double z = g.state.x(2, at(0, i));
        const double y = 2.0 + a * std::cosh((z - span / 2) / a) - a * std::cosh(span / (2 * a));
        sum += (g.state.x(1, at(0, i)) - y) * (g.state.x(1, at(0, i)) - y);
    }
    row.rms_shape_m = std::sqrt(sum / static_cast<double>(n));
    return row;
}

}  // namespace

Result<void> run_error(const BenchOptions& options) {
    const Machine machine = describe_machine();
    const HorizonPlan plan;
    const auto make_reference = [&](int substeps) {
        return sweep_world(ClothModel::classic, substeps, ClothMaterial{}.iterations, CollisionMode::brute_force, options.threads);
    };
    auto reference = converged_reference(make_reference, plan, reference_first_substeps, reference_max_substeps,
                                         reference_tolerance_m);
    if (!reference) return fail("error: " + reference.error().message);
    std::fprintf(stderr, "drape bench error: reference at %d substeps, %.3f mm from its refinement%s\n", reference->substeps,
                 1000 * reference->converged_m, reference->converged ? "" : " (NOT converged)");

    std::vector<SweepRow> rows;
    for (ClothModel model : {ClothModel::simplified, ClothModel::classic})
        for (CollisionMode collision : {CollisionMode::candidate_lists, CollisionMode::brute_force})
            for (int substeps : {1, 2, 4, 16})
                for (int iterations : {1, 2, 4, 8}) {
                    auto row = measure({model, substeps, iterations, collision}, plan, *reference, options.threads);
                    if (!row) return fail("error: " + row.error().message);
                    rows.push_back(*row);
                }
    // The paper's integrator (docs/cloth.md "Two integrators"): with its own substeps (its
    // stability bound; fewer diverge) and with twice as many, both models, the default rounds.
    for (ClothModel model : {ClothModel::simplified, ClothModel::classic})
        for (int substeps : {0, 256}) {
            SweepRow paper_row{model, substeps, ClothMaterial{}.iterations, CollisionMode::candidate_lists};
            paper_row.integrator = ClothIntegrator::paper;
            auto row = measure(paper_row, plan, *reference, options.threads);
            if (!row) return fail("error: " + row.error().message);
            rows.push_back(*row);
        }
    const GarmentDescription shipped;
    const int default_iterations = ClothMaterial{}.iterations;
    auto default_row = measure({shipped.model, 0, default_iterations, shipped.collision}, plan, *reference, options.threads);
    if (!default_row) return fail("error: " + default_row.error().message);
    rows.push_back(*default_row);
    const std::size_t default_index = rows.size() - 1;

    // Pareto front: no other configuration is both faster and more accurate (the default among them).
    std::vector<std::size_t> order(rows.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](auto a, auto b) {
        return rows[a].ms_per_frame != rows[b].ms_per_frame ? rows[a].ms_per_frame < rows[b].ms_per_frame
                                                            : rows[a].rms_error_m < rows[b].rms_error_m;
    });
    std::vector<bool> pareto(rows.size(), false);
    double best = INFINITY;
    for (auto i : order)
        if (rows[i].rms_error_m < best) {
            best = rows[i].rms_error_m;
            pareto[i] = true;
        }
    std::vector<std::size_t> dominating;   // configurations both faster and closer than the default
    for (std::size_t i = 0; i < rows.size(); ++i)
        if (rows[i].ms_per_frame < default_row->ms_per_frame && rows[i].rms_error_m < default_row->rms_error_m)
            dominating.push_back(i);

    std::vector<OscillatorRow> oscillator_rows;
    for (double n : {400.0, 200.0, 100.0, 50.0, 25.0, 12.0, 8.0, 5.0, 3.5, 3.2, 3.0}) {
        auto row = oscillator(n);
        if (!row) return fail("error: " + row.error().message);
        oscillator_rows.push_back(*row);
    }
    std::vector<ChainRow> chain_rows;
    for (int n : {11, 21, 41, 81}) {
        auto row = hanging_chain(n);
        if (!row) return fail("error: " + row.error().message);
        chain_rows.push_back(*row);
    }
    auto sheet_rows = sheet_convergence(plan.horizon_frames);
    if (!sheet_rows) return fail("error: " + sheet_rows.error().message);

    auto to_json = [](const SweepRow& r) {
        return nlohmann::json{{"integrator", cloth_integrator_name(r.integrator)},
                              {"model", model_name(r.model)},
                              {"substeps", r.substeps == 0 ? nlohmann::json("auto") : nlohmann::json(r.substeps)},
                              {"iterations", r.iterations},
                              {"collision", collision_name(r.collision)},
                              {"ms_per_frame", r.ms_per_frame},
                              {"rms_error_m", r.rms_error_m},
                              {"strain_max", r.strain_max},
                              {"strain_p99", r.strain_p99},
                              {"penetration_after_m", r.penetration_after_m},
                              {"max_strain", r.strain_max},
                              {"max_penetration_m", r.penetration_after_m},
                              {"mean_substeps", r.mean_substeps}};
    };
    nlohmann::json json;
    json["reference"] = reference_json(*reference);
    json["reference"]["model"] = "classic";
    json["reference"]["collision"] = "brute_force";
    json["reference"]["iterations"] = ClothMaterial{}.iterations;
    json["horizons"] = horizon_plan_json(plan);
    json["rows"] = nlohmann::json::array();
    for (std::size_t i = 0; i < default_index; ++i) {
        json["rows"].push_back(to_json(rows[i]));
        json["rows"].back()["pareto"] = static_cast<bool>(pareto[i]);
    }
    json["default"] = to_json(*default_row);
    json["default"]["pareto"] = static_cast<bool>(pareto[default_index]);

    Report report("Error against run time (`error`)", options, machine);
    report.paragraph(
        "Walking default avatar, default skirt (" + std::to_string(reference->states.end_x.front().cols()) +
        " particles). Reference: the classic model (stretch, shear and bend springs) with brute-force collision and the "
        "default material (" + std::to_string(ClothMaterial{}.iterations) + " constraint rounds per substep) at " +
        std::to_string(reference->substeps) + " fixed substeps per 1/60 s frame, the step chosen by its own convergence "
        "(below). The error of a configuration is what its shortcuts cost (fewer springs, coarser steps, fewer "
        "rounds, candidate lists). Beside the shipped solver's sweep, the paper's integrator as written (docs/cloth.md "
        "\"Two integrators\": explicit springs, Provot after the step) with its own substeps (auto: its stability "
        "bound; fewer diverge) and at 256, candidate lists, the default rounds, both models, against the same "
        "reference. " + horizon_plan_text(plan) +
        " ms per frame: the garment's simulation phase (frame profiler), one run per configuration, the median frame "
        "from the first horizon on. Strain (max, p99) and penetration after the frame are measured after every frame "
        "from the first horizon on, as `drape play --stats` measures them: strain of every structural spring with a "
        "free end, the deepest free particle inside an ellipsoid.");
    report.heading("Reference convergence");
    report.paragraph(reference_text(*reference, reference_tolerance_m));
    report.heading("Default configuration");
    std::string verdict;
    if (dominating.empty()) {
        verdict = "No swept configuration is both faster and closer to the reference: the default is on the Pareto front.";
    } else {
        verdict = "**The default is not on the Pareto front**: " + std::to_string(dominating.size()) +
                  " swept configuration(s) are both faster and closer to the reference, e.g. " +
                  model_name(rows[dominating.front()].model) + ", " + std::to_string(rows[dominating.front()].substeps) +
                  " substeps, " + std::to_string(rows[dominating.front()].iterations) + " rounds, " +
                  collision_name(rows[dominating.front()].collision) + " (" + fixed(rows[dominating.front()].ms_per_frame, 4) +
                  " ms, " + fixed(1000 * rows[dominating.front()].rms_error_m, 2) + " mm).";
    }
    report.paragraph(std::string(model_name(default_row->model)) + " model, automatic substeps (mean " +
                     fixed(default_row->mean_substeps, 2) + " per frame), " + std::to_string(default_iterations) +
                     " constraint rounds, " + collision_name(default_row->collision) + ": **" +
                     fixed(default_row->ms_per_frame, 4) + " ms per frame, RMS error " +
                     fixed(1000 * default_row->rms_error_m, 2) + " mm**, strain max " +
                     fixed(100 * default_row->strain_max, 1) + " % (p99 " + fixed(100 * default_row->strain_p99, 1) +
                     " %), penetration after the frame " + fixed(1000 * default_row->penetration_after_m, 2) + " mm. " +
                     verdict);
    report.heading("Sweep");
    std::vector<std::vector<std::string>> table;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto& r = rows[i];
        const bool is_reference = r.integrator == ClothIntegrator::shipped && r.model == ClothModel::classic &&
                                  r.collision == CollisionMode::brute_force &&
                                  r.substeps == reference->substeps && r.iterations == ClothMaterial{}.iterations;
        table.push_back({cloth_integrator_name(r.integrator), std::string(model_name(r.model)) + (i == default_index ? " (default)" : "") +
                             (is_reference ? " (the reference's settings)" : ""),
                         r.substeps == 0 ? "auto (" + fixed(r.mean_substeps, 2) + ")" : std::to_string(r.substeps),
                         std::to_string(r.iterations), collision_name(r.collision), fixed(r.ms_per_frame, 4),
                         fixed(1000 * r.rms_error_m, 2), fixed(100 * r.strain_max, 1), fixed(100 * r.strain_p99, 1),
                         fixed(1000 * r.penetration_after_m, 2), pareto[i] ? "yes" : ""});
    }
    report.table({"integrator", "model", "substeps", "rounds", "collision", "ms / frame", "RMS error (mm)", "strain max (%)",
                  "strain p99 (%)", "penetration after (mm)", "Pareto"},
                 table);
    // How each model's error follows the step (candidate lists, the default rounds).
    std::string trend;
    for (ClothModel model : {ClothModel::simplified, ClothModel::classic}) {
        std::string figures, steps;
        for (std::size_t i = 0; i < default_index; ++i) {
            const auto& r = rows[i];
            if (r.integrator != ClothIntegrator::shipped || r.model != model || r.collision != CollisionMode::candidate_lists ||
                r.iterations != default_iterations)
                continue;
            figures += (figures.empty() ? "" : " -> ") + fixed(1000 * r.rms_error_m, 2);
            steps += (steps.empty() ? "" : ", ") + std::to_string(r.substeps);
        }
        trend += std::string(trend.empty() ? "" : "; ") + model_name(model) + ": " + figures + " mm at " + steps + " substeps";
    }
    report.paragraph("Error as the step shrinks (candidate lists, " + std::to_string(default_iterations) +
                     " rounds): " + trend + ". A row with the reference's own settings is at zero by construction.");

    // Plot: error against time, one series per model x collision, the front and the default.
    std::vector<PlotData> data;
    const char* series_names[4] = {"sl", "sb", "cl", "cb"};
    for (int s = 0; s < 4; ++s) {
        PlotData d{series_names[s], {}};
        for (std::size_t i = 0; i < default_index; ++i) {
            const auto& r = rows[i];
            if (r.integrator == ClothIntegrator::shipped && (r.model == ClothModel::classic) == (s >= 2) &&
                (r.collision == CollisionMode::brute_force) == (s % 2 == 1))
                d.rows.push_back({r.ms_per_frame, 1000 * r.rms_error_m});
        }
        data.push_back(d);
    }
    PlotData paper_points{"paper", {}};
    for (std::size_t i = 0; i < default_index; ++i)
        if (rows[i].integrator == ClothIntegrator::paper) paper_points.rows.push_back({rows[i].ms_per_frame, 1000 * rows[i].rms_error_m});
    data.push_back(paper_points);
    PlotData front{"front", {}};
    for (auto i : order)
        if (pareto[i]) front.rows.push_back({rows[i].ms_per_frame, 1000 * rows[i].rms_error_m});
    data.push_back(front);
    data.push_back({"def", {{default_row->ms_per_frame, 1000 * default_row->rms_error_m}}});
    const std::string script =
        "set title 'Error against run time (reference: classic, brute force, " + std::to_string(reference->substeps) +
        " substeps)'\n"
        "set xlabel 'garment ms per frame'\nset ylabel 'RMS error over " + fixed(plan.horizon_frames * frame_dt_s, 3) +
        " s (mm)'\nset logscale xy\nset grid\nset key outside right\n"
        "plot $sl using 1:2 with points pt 7 lc rgb '#3060c0' title 'simplified + lists', "
        "$sb using 1:2 with points pt 5 lc rgb '#60a0e0' title 'simplified + brute force', "
        "$cl using 1:2 with points pt 9 lc rgb '#c04030' title 'classic + lists', "
        "$cb using 1:2 with points pt 11 lc rgb '#e09060' title 'classic + brute force', "
        "$paper using 1:2 with points pt 13 ps 1.5 lc rgb '#8040a0' title \"paper's integrator\", "
        "$front using 1:2 with steps lw 2 lc rgb '#202020' title 'Pareto front', "
        "$def using 1:2 with points pt 3 ps 3 lw 2 lc rgb '#10a010' title 'default (auto substeps)'" +
        (std::isfinite(reference->converged_m) ? ", " + fixed(1000 * reference->converged_m, 4) +
                                                     " with lines dt 2 lc rgb '#808080' title \"reference's own convergence\""
                                               : std::string()) + "\n";
    report.plot("error.png", "Error against ms per frame with the Pareto front", data, script, 1000, 560);

    report.heading("Analytic reference: a mass on a spring");
    report.paragraph(
        "One 0.1 kg particle on a 40 N/m spring standing on a pin (a 2 x 2 rectangle garment: two such springs side "
        "by side, moving together; drag off, one substep per step), released from the spring's rest length: an "
        "oscillation of amplitude mg/k about the equilibrium, the spring shorter than its rest length throughout (the "
        "tethers keep a hanging particle within the rest length of its line, so a hanging mass cannot swing below "
        "it). 20 periods at each step h. The springs are constraints in compliance form (systems/cloth/constraints.hpp): "
        "for one linear spring that is backward Euler, which turns the phase by atan(omega h) and scales the "
        "amplitude by 1 / sqrt(1 + (omega h)^2) each step: period 2 pi h / atan(omega h) (shown as expected), stable "
        "at any step, damped. The Provot limit is raised to its maximum (1000 %); a run counts as unstable once the "
        "displacement exceeds 20x the amplitude. Amplitude drift: the largest displacement in period 19 against period "
        "0 (expected from the factor above); the period is measured from upward zero crossings while the swing is "
        "above 0.1 % of its start.");
    std::vector<std::vector<std::string>> osc;
    for (const auto& r : oscillator_rows)
        osc.push_back({fixed(r.steps_per_period, 1), fixed(1000 * r.h_s, 3), fixed(r.omega_h, 3),
                       r.stable ? fixed(100 * r.period_error, 3) : "-", fixed(100 * r.expected_period_error, 3),
                       r.stable ? fixed(100 * r.amplitude_drift, 3) : "-", fixed(100 * r.expected_amplitude_drift, 3),
                       r.stable ? "stable" : "**unstable**"});
    report.table({"steps / period", "h (ms)", "omega h", "period error (%)", "expected (%)", "amplitude drift (%)",
                  "expected (%)", ""},
                 osc);
    std::vector<PlotData> osc_data{{"o", {}}};
    for (const auto& r : oscillator_rows)
        if (r.stable && std::isfinite(r.period_error) && std::isfinite(r.amplitude_drift))
            osc_data[0].rows.push_back({r.omega_h, std::abs(100 * r.period_error) + 1e-6, std::abs(100 * r.expected_period_error) + 1e-6,
                                        std::abs(100 * r.amplitude_drift) + 1e-6, std::abs(100 * r.expected_amplitude_drift) + 1e-6});
    const std::string osc_script =
        "set title 'Mass on a spring: the compliance-form spring against backward Euler'\n"
        "set xlabel 'omega h'\nset ylabel '|error| (%)'\nset logscale xy\nset grid\nset key left top\n"
        "plot $o using 1:2 with linespoints pt 7 title 'period error, measured', "
        "$o using 1:3 with lines dt 2 title 'period error, backward Euler', "
        "$o using 1:4 with linespoints pt 5 title 'amplitude loss over 19 periods, measured', "
        "$o using 1:5 with lines dt 3 title 'amplitude loss, backward Euler'\n";
    if (osc_data[0].rows.empty())
        report.missing_plot("no oscillator run gave a period and an amplitude");
    else
        report.plot("error_oscillator.png", "Oscillator period and amplitude error against step size", osc_data, osc_script);

    report.heading("Convergence without a body");
    report.paragraph(
        "The reference's refinement ladder with the body taken away: a 16 x 16 sheet (classic model, default "
        "material) pinned along one edge in world space, released horizontally and stepped 20 frames at 16 substeps; "
        "from that swinging state, the RMS distance between its end at n and at 2n substeps after one frame and after "
        "a horizon (" + std::to_string(plan.horizon_frames) + " frames). Against the ladder on the walking body above, "
        "it shows what the integration alone resolves. Finer steps meet the precision of the garment's float "
        "positions: at 128 substeps gravity moves a particle at rest by g h^2 = " +
        fixed(1e6 * standard_gravity_m_s2 * std::pow(frame_dt_s / 128, 2), 3) + " micrometre per substep, against a "
        "float spacing of " + fixed(1e6 * (std::nextafter(2.0f, 3.0f) - 2.0f), 3) + " micrometre at 2 m height.");
    std::vector<std::vector<std::string>> sheet;
    for (const auto& r : *sheet_rows)
        sheet.push_back({std::to_string(r.substeps) + " vs " + std::to_string(2 * r.substeps), fixed(1000 * r.one_frame_m, 4),
                         fixed(1000 * r.horizon_m, 3)});
    report.table({"substeps", "after 1 frame (mm)", "after a horizon (mm)"}, sheet);
    json["sheet_without_body"] = nlohmann::json::array();
    for (const auto& r : *sheet_rows)
        json["sheet_without_body"].push_back({{"substeps", r.substeps}, {"one_frame_m", r.one_frame_m}, {"horizon_m", r.horizon_m}});

    report.heading("Analytic reference: a chain against the catenary");
    report.paragraph(
        "Two warp lines 5 cm apart joined by weft springs, each 1 m rest length and 0.1 kg, their ends pinned 0.8 m apart, settled for 25 s under "
        "drag (1/240 s steps, automatic substeps, the same chain stiffness EA for every particle count, Provot limit "
        "10 %). Catenary sag: of an inextensible chain as long as the settled one (the springs stretch a little); "
        "rest-length sag: of the unstretched 1 m chain. Shape RMS: vertical distance of the particles from that "
        "catenary.");
    std::vector<std::vector<std::string>> chain;
    for (const auto& r : chain_rows)
        chain.push_back({std::to_string(r.particles), fixed(1000 * r.sag_m, 2), fixed(1000 * r.catenary_sag_m, 2),
                         fixed(100 * (r.sag_m / r.catenary_sag_m - 1), 3), fixed(1000 * r.inextensible_sag_m, 2),
                         fixed(1000 * r.rms_shape_m, 3), fixed(100 * r.mean_strain, 2)});
    report.table({"particles", "sag (mm)", "catenary sag (mm)", "sag error (%)", "rest-length sag (mm)", "shape RMS (mm)",
                  "mean strain (%)"},
                 chain);

    return finish(report, options, json);
}

}  // namespace drape::bench
