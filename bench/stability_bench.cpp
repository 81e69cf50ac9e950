// `drape bench stability`: stiff and extreme cases, divergence judged apart from quality.
//
// 1. The whole cloth: stretch modulus x fixed step (one frame each) x motion x garment, with
//    the cloth's automatic substeps and with one substep per step, the shipped material among
//    the moduli. Each run is judged for divergence (stability_bench.hpp: non-finite values, a
//    particle beyond the reach of its pin, energy growth) and measured for quality after every
//    whole frame (systems/cloth/garment_quality.hpp: strain max and p99, penetration). A run
//    whose automatic substeps reached the cap (ClothSolverSettings::max_substeps) could not
//    take what the rule asked: it is reported as capped, apart from the divergence count.
// 2. The explicit limit of the integrator alone (no constraints, no Provot, no collision): a
//    hanging chain of the skirt's particle mass and spacing whose springs are explicit forces,
//    stepped by symplectic Euler through the cloth's own prediction (integrator.hpp's
//    predict_particles for gravity and drag, the spring impulse added before it), against
//    the bound of the linearised chain, h < 2 / sqrt(lambda_max(M^-1 K)).
#include "bench/stability_bench.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <queue>

#include <Eigen/Eigenvalues>

#include "bench/characters.hpp"
#include "bench/report.hpp"
#include "bench/world.hpp"
#include "drape/components/animation_player.hpp"
#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/transform.hpp"
#include "drape/systems/cloth/garment_config.hpp"
#include "drape/systems/cloth/garment_quality.hpp"
#include "drape/systems/cloth/garment_step.hpp"
#include "drape/systems/cloth/integrator.hpp"
#include "drape/systems/cloth/substeps.hpp"
#include "drape/systems/teleport_guard_system.hpp"

namespace drape::bench {

PinReach pin_reach(std::size_t particles, const StructuralSprings& springs, const std::vector<std::uint32_t>& pinned) {
    PinReach r;
    r.pin.assign(particles, PinReach::no_pin);
    r.rest_m.assign(particles, std::numeric_limits<double>::infinity());
    std::vector<std::vector<std::pair<std::uint32_t, double>>> next(particles);
    for (std::size_t s = 0; s < springs.springs.size(); ++s) {
        const auto [a, b] = springs.springs[s];
        if (a >= particles || b >= particles) continue;
        next[a].push_back({b, springs.rest_m[s]});
        next[b].push_back({a, springs.rest_m[s]});
    }
    using Item = std::pair<double, std::uint32_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
    for (std::uint32_t p : pinned) {
        if (p >= particles) continue;
        r.pin[p] = p;
        r.rest_m[p] = 0;
        open.push({0.0, p});
    }
    while (!open.empty()) {
        const auto [d, p] = open.top();
        open.pop();
        if (d > r.rest_m[p]) continue;
        for (const auto& [q, length] : next[p]) {
            if (d + length < r.rest_m[q]) {
                r.rest_m[q] = d + length;
                r.pin[q] = r.pin[p];
                open.push({r.rest_m[q], q});
            }
        }
    }
    std::vector<double> longest(particles, 0.0);  // per pin
    for (std::size_t p = 0; p < particles; ++p)
        if (r.pin[p] != PinReach::no_pin) longest[r.pin[p]] = std::max(longest[r.pin[p]], r.rest_m[p]);
    r.line_m.assign(particles, std::numeric_limits<double>::infinity());
    for (std::size_t p = 0; p < particles; ++p)
        if (r.pin[p] != PinReach::no_pin) r.line_m[p] = longest[r.pin[p]];
    return r;
}

double worst_reach_ratio(const Matrix3X& x, const PinReach& reach) {
    double worst = 0;
    const auto n = static_cast<std::size_t>(x.cols());
    for (std::size_t p = 0; p < n && p < reach.pin.size(); ++p) {
        const double rest = reach.line_m[p];
        if (!(reach.rest_m[p] > 0) || !std::isfinite(rest)) continue;
        const double d = (x.col(static_cast<Eigen::Index>(p)) - x.col(static_cast<Eigen::Index>(reach.pin[p]))).norm();
        if (!std::isfinite(d)) return std::numeric_limits<double>::infinity();
        worst = std::max(worst, d / rest);
    }
    return worst;
}

Divergence classify_divergence(const RunTrace& t, const DivergenceLimits& limits) {
    if (t.non_finite_values > 0)
        return {true, "non-finite values (" + std::to_string(t.non_finite_values) + ", " + t.frame_word + " " +
                          std::to_string(t.first_non_finite_frame) + ")"};
    if (!(t.worst_reach_ratio <= 1 + limits.reach_factor))
        return {true, "a particle " + fixed(t.worst_reach_ratio, 2) + "x its line's rest length from its pin (" + t.frame_word + " " +
                          std::to_string(t.worst_reach_frame) + ")"};
    const std::size_t n = t.energy_J.size();
    if (n >= 3) {
        const std::size_t late = n - n / 3;
        const double early_peak = *std::max_element(t.energy_J.begin(), t.energy_J.begin() + static_cast<std::ptrdiff_t>(late));
        const double late_peak = *std::max_element(t.energy_J.begin() + static_cast<std::ptrdiff_t>(late), t.energy_J.end());
        if (!std::isfinite(late_peak) || (late_peak > limits.energy_growth * early_peak && late_peak > limits.energy_floor_J))
            return {true, "energy growth (" + fixed(late_peak, 3) + " J in the last third, " + fixed(early_peak, 3) +
                              " J before)"};
    }
    return {};
}

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

/// Stretch moduli, N/m; 0 stands for the shipped material (the garment's as built, cotton).
constexpr double moduli[] = {10, 1e2, 1e3, 0, 1e4, 1e5, 1e6};
/// The dress has 12x the skirt's particles: a coarser set keeps the benchmark within minutes.
constexpr double dress_moduli[] = {10, 0, 1e6};
std::vector<double> modulus_set(GarmentType g) {
    if (g == GarmentType::dress) return {std::begin(dress_moduli), std::end(dress_moduli)};
    return {std::begin(moduli), std::end(moduli)};
}
constexpr double steps_s[] = {1.0 / 240, 1.0 / 60, 1.0 / 15, 1.0 / 4};
std::string step_label(double dt) {
    if (dt < 0.005) return "1/240";
    if (dt < 0.02) return "1/60";
    if (dt < 0.1) return "1/15";
    return "1/4";
}
constexpr double run_s = 0.75;
constexpr int min_frames = 16;
const DivergenceLimits base_limits{};

struct Case {
    std::string name;
    ClothIntegrator integrator = ClothIntegrator::shipped;
    GarmentType garment = GarmentType::skirt;
    Motion motion = Motion::walk;
    double k_N_m = 0;
    bool default_material = false;
    double frame_dt_s = 0;
    bool auto_substeps = true;
    Divergence divergence;
    bool capped = false;         ///< Automatic substeps reached the cap on some frame.
    int capped_frames = 0;
    double strain_max = 0, strain_p99 = 0, penetration_m = 0;
    double mean_substeps = 0, worst_reach = 0;
    double body_speed_m_s = 0;   ///< The fastest surface of the body over the run (world frame).
    double energy_peak_J = 0;    ///< The garment's kinetic energy, its peak over the run.
};

std::string outcome(const Case& c) {
    if (c.capped) return c.divergence.diverged ? "capped, diverged" : "capped";
    return c.divergence.diverged ? "diverged" : "ok";
}

// The fastest a surface of the character's ellipsoids moves in the world this step: each
// one's centre speed plus its spin times its largest radius.
double body_surface_speed_m_s(Registry& r, Entity character) {
    double fastest = 0;
    r.view<EllipsoidCollider>().each([&](Entity, const EllipsoidCollider& e) {
        if (e.character != character) return;
        fastest = std::max(fastest, static_cast<double>(e.velocity_m_s.norm() +
                                                        e.angular_velocity_rad_s.norm() * e.radii_m.maxCoeff()));
    });
    return fastest;
}

double garment_mass_kg(const Garment& g) {
    double m = 0;
    for (Eigen::Index i = 0; i < g.state.inv_mass.size(); ++i)
        if (g.state.inv_mass[i] > 0) m += 1.0 / g.state.inv_mass[i];
    return m;
}

/// Runs one case on a world built for its garment and step.
Result<void> run_case(World& world, const ClothMaterial& material, const PinReach& reach, double start_s, Case& c) {
    Registry& r = world.registry;
    const Entity character = world.characters.at(0);
    auto& transform = r.get<Transform>(character);
    auto& player = r.get<AnimationPlayer>(character);
    const Transform home = transform;
    // The body back home at `start_s` into its clip (playing) for one step, so that its
    // colliders are there too, and a case gives the same result whichever cases ran before
    // it (the clip went on from where the last case left it: a spin at 1e4 N/m diverged
    // after the softer spins and not alone); that jump home is no motion (a spin's last
    // case ends half a turn away: its colliders would carry hundreds of rad/s into the
    // garment's reset), so their motion is forgotten, as after a teleport; then the garment
    // at rest around it.
    player.speed = 1;
    player.playing = true;
    player.time_s = start_s;
    player.cycles = 0;
    if (auto ok = step_world(world, c.frame_dt_s); !ok) return fail(ok.error().message);
    forget_collider_motion(r, character);
    if (auto ok = set_garment_material(r, world.garments.at(0), material); !ok) return fail(ok.error().message);
    reset_garments(world);
    if (const double start = worst_reach_ratio(first_garment(world).state.x, reach); !(start <= 1 + base_limits.reach_factor))
        return fail("the garment starts " + fixed(start, 2) + "x its line's rest length from its pins");
    player.speed = c.motion == Motion::run ? 2.5 : 1.0;
    if (auto ok = set_time_scale(world, c.motion == Motion::time_scale ? 10.0 : 1.0); !ok) return fail(ok.error().message);

    DivergenceLimits limits = base_limits;
    limits.energy_floor_J = 0.5 * garment_mass_kg(first_garment(world));  // at 1 m/s
    // The cap the automatic substeps can reach: the paper's integrator's stability need has
    // its own (ClothSolverSettings::max_stability_substeps), the motion need the common one.
    const ClothSolverSettings settings;
    const int cap = settings.max_substeps;
    const int stability_cap = c.integrator == ClothIntegrator::paper ? std::max(cap, settings.max_stability_substeps) : cap;
    const std::uint64_t non_finite_before = first_garment(world).counters.non_finite_values;
    StrainHistogram histogram;
    RunTrace trace;
    const int frames = std::max(min_frames, static_cast<int>(std::lround(run_s / c.frame_dt_s)));
    const int event = frames / 3;
    double substeps = 0;
    int frame = 0;
    for (; frame < frames; ++frame) {
        switch (c.motion) {
            case Motion::spin:
                transform.rotation = Quat(Eigen::AngleAxis<Real>(static_cast<Real>(30.0 * c.frame_dt_s), Vec3::UnitY())) *
                                     transform.rotation;
                break;
            case Motion::teleport:
                if (frame == event) transform.position += Vec3(100, 0, 0);
                break;
            case Motion::sudden_stop:
                if (frame < event)
                    transform.position += Vec3(0, 0, static_cast<Real>(5.0 * c.frame_dt_s));  // 5 m/s forward
                else
                    player.playing = false;  // stops dead: no travel, no animation
                break;
            default: break;
        }
        if (auto ok = step_world(world, c.frame_dt_s); !ok) return fail(ok.error().message);
        const Garment& g = first_garment(world);
        c.body_speed_m_s = std::max(c.body_speed_m_s, body_surface_speed_m_s(r, character));
        substeps += g.counters.substeps;
        if (c.auto_substeps && (g.counters.substeps_stability >= stability_cap || g.counters.substeps_motion >= cap)) {
            c.capped = true;
            ++c.capped_frames;
        }
        const std::uint64_t bad = g.counters.non_finite_values - non_finite_before + count_non_finite(g);
        if (bad > 0) {
            trace.non_finite_values = bad;
            trace.first_non_finite_frame = frame;
            ++frame;
            break;
        }
        const GarmentQuality q = measure_garment(r, g, &histogram);
        c.strain_max = std::max(c.strain_max, static_cast<double>(q.strain_max));
        c.penetration_m = std::max(c.penetration_m, static_cast<double>(q.penetration_m));
        trace.energy_J.push_back(kinetic_energy_J(g.state.v, g.state.inv_mass));
        const double ratio = worst_reach_ratio(g.state.x, reach);
        if (ratio > trace.worst_reach_ratio || trace.worst_reach_frame < 0) {
            trace.worst_reach_ratio = ratio;
            trace.worst_reach_frame = frame;
        }
        if (!(ratio <= 1 + limits.reach_factor)) {
            ++frame;
            break;  // ran away: the rest of the run says nothing more
        }
    }
    if (!trace.energy_J.empty()) c.energy_peak_J = *std::max_element(trace.energy_J.begin(), trace.energy_J.end());
    c.divergence = classify_divergence(trace, limits);
    c.worst_reach = trace.worst_reach_ratio;
    c.strain_p99 = histogram.samples() > 0 ? static_cast<double>(histogram.percentile(0.99)) : NAN;
    c.mean_substeps = substeps / std::max(1, frame);
    transform = home;
    if (auto ok = set_time_scale(world, 1.0); !ok) return fail(ok.error().message);
    return {};
}

// ---- The integrator alone: a hanging chain with explicit springs.

struct Chain {
    int particles = 20;          ///< The first is pinned.
    Real rest_m = 0.03f;
    Real mass_kg = 2e-4f;
    Real drag_N_s_m = 0;
};

/// Largest stable step of symplectic Euler for the chain's linearised springs: 2 / sqrt(lambda_max(M^-1 K)).
double chain_bound_s(const Chain& chain, double k) {
    const int n = chain.particles - 1;  // free particles
    Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) {
        a(i, i) = (i + 1 < n ? 2 : 1) * k / chain.mass_kg;
        if (i + 1 < n) a(i, i + 1) = a(i + 1, i) = -k / chain.mass_kg;
    }
    const double lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
    return 2 / std::sqrt(lambda);
}

struct ChainCase {
    double k_N_m = 0, h_s = 0;
    Divergence divergence;
};

constexpr double chain_run_s = 1.0;
constexpr int chain_min_steps = 60;

/// The chain hanging straight down at rest length, released under gravity, stepped with
/// explicit spring forces and the cloth's prediction.
Divergence run_chain(const Chain& chain, double k, double h) {
    const int n = chain.particles;
    Matrix3X x(3, n), v = Matrix3X::Zero(3, n);
    VectorX inv_mass = VectorX::Constant(n, 1 / chain.mass_kg), drag = VectorX::Constant(n, chain.drag_N_s_m);
    inv_mass[0] = 0;
    StructuralSprings springs;
    for (int i = 0; i < n; ++i) {
        x.col(i) = Vec3(0, -chain.rest_m * static_cast<Real>(i), 0);
        if (i > 0) {
            springs.springs.push_back({static_cast<std::uint32_t>(i - 1), static_cast<std::uint32_t>(i)});
            springs.rest_m.push_back(chain.rest_m);
        }
    }
    const PinReach reach = pin_reach(static_cast<std::size_t>(n), springs, {0});
    DivergenceLimits limits = base_limits;
    limits.energy_floor_J = 0.5 * chain.mass_kg * (n - 1);  // at 1 m/s
    RunTrace trace;
    trace.frame_word = "step";
    const Vec3 gravity(0, -standard_gravity_m_s2, 0);
    const int steps = std::max(chain_min_steps, static_cast<int>(std::ceil(chain_run_s / h)));
    const Real hr = static_cast<Real>(h);
    const Real kr = static_cast<Real>(k);
    for (int step = 0; step < steps; ++step) {
        for (int i = 1; i < n; ++i) {  // explicit Hooke springs: the impulse h F
            const Vec3 d = x.col(i) - x.col(i - 1);
            const Real length = d.norm();
            const Vec3 f = length > 0 ? Vec3(kr * (length - chain.rest_m) / length * d) : Vec3::Zero();
            v.col(i) -= hr * inv_mass[i] * f;
            v.col(i - 1) += hr * inv_mass[i - 1] * f;
        }
        predict_particles(x, v, inv_mass, drag, 0, n, AnchorMotion{}, InertiaScales{}, gravity, hr);
        if (!x.allFinite() || !v.allFinite()) {
            trace.non_finite_values = static_cast<std::uint64_t>((!x.array().isFinite()).count() + (!v.array().isFinite()).count());
            trace.first_non_finite_frame = step;
            break;
        }
        trace.energy_J.push_back(kinetic_energy_J(v, inv_mass));
        const double ratio = worst_reach_ratio(x, reach);
        if (ratio > trace.worst_reach_ratio) {
            trace.worst_reach_ratio = ratio;
            trace.worst_reach_frame = step;
        }
        if (!(ratio <= 1 + limits.reach_factor)) break;
    }
    return classify_divergence(trace, limits);
}

/// The chain of the skirt: its median free-particle mass and warp spacing, its drag.
Chain chain_of(const Garment& g) {
    Chain c;
    std::vector<double> masses, drags;
    for (Eigen::Index i = 0; i < g.state.inv_mass.size(); ++i)
        if (g.state.inv_mass[i] > 0) masses.push_back(1.0 / g.state.inv_mass[i]);
    std::vector<double> rest(g.fabric->warp1.rest_m.begin(), g.fabric->warp1.rest_m.end());
    c.mass_kg = static_cast<Real>(median(masses));
    c.rest_m = static_cast<Real>(median(rest));
    c.particles = static_cast<int>(g.fabric->particles_per_line);
    const double area = median(std::vector<double>(g.fabric->area_m2.begin(), g.fabric->area_m2.end()));
    c.drag_N_s_m = static_cast<Real>(g.config.material.drag_N_s_m3 * area);
    return c;
}

std::string k_label(double k) { return fixed(k, 0); }

}  // namespace

Result<void> run_stability(const BenchOptions& options) {
    const Machine machine = describe_machine();
    std::vector<Case> cases;
    ClothMaterial shipped;
    Chain chain;
    std::size_t skirt_particles = 0, dress_particles = 0;
    // The paper's integrator on the skirt only: its automatic substeps grow with sqrt(k), and
    // the dress (12x the particles) at 1e6 N/m would take hours.
    for (ClothIntegrator integrator : {ClothIntegrator::shipped, ClothIntegrator::paper})
    for (GarmentType garment : {GarmentType::skirt, GarmentType::dress}) {
        if (integrator == ClothIntegrator::paper && garment == GarmentType::dress) continue;
        for (double dt : steps_s) {
            std::fprintf(stderr, "drape bench stability: %s integrator, %s, step %s s\n", cloth_integrator_name(integrator),
                         garment_type_name(garment), step_label(dt).c_str());
            for (bool automatic : {true, false}) {
                WorldSpec spec;
                spec.integrator = integrator;
                spec.garment = garment;
                spec.fixed_dt_s = dt;
                spec.threads = options.threads;
                spec.substeps = automatic ? 0 : 1;
                spec.warp_solve = options.warp_solve;
                auto world = build_bench_world(spec);
                if (!world) return fail("stability: " + world.error().message);
                const Garment& g = first_garment(*world);
                const ClothMaterial built = g.config.material;
                if (garment == GarmentType::skirt) {
                    shipped = built;
                    chain = chain_of(g);
                    skirt_particles = static_cast<std::size_t>(g.state.x.cols());
                } else {
                    dress_particles = static_cast<std::size_t>(g.state.x.cols());
                }
                const PinReach reach = pin_reach(static_cast<std::size_t>(g.state.x.cols()), structural_springs(*g.fabric),
                                                 pinned_particles(g));
                for (double k : modulus_set(garment))
                    for (Motion motion : motions) {
                        Case c;
                        c.integrator = integrator;
                        c.garment = garment;
                        c.motion = motion;
                        c.default_material = k == 0;
                        ClothMaterial material = built;
                        if (!c.default_material) material.stretch_N_m = static_cast<Real>(k);
                        c.k_N_m = material.stretch_N_m;
                        c.frame_dt_s = dt;
                        c.auto_substeps = automatic;
                        c.name = std::string(cloth_integrator_name(integrator)) + "/" + garment_type_name(garment) + "/" + motion_name(motion) + "/k=" +
                                 k_label(c.k_N_m) + (c.default_material ? " (shipped)" : "") + "/dt=" + step_label(dt) +
                                 (automatic ? "/auto" : "/1-substep");
                        if (!matches_filter(c.name, options.filter)) continue;
                        if (auto ok = run_case(*world, material, reach, options.start_s, c); !ok)
                            return fail("stability: " + c.name + ": " + ok.error().message);
                        cases.push_back(c);
                    }
            }
        }
    }

    if (cases.empty()) return fail("stability: no case matched (--filter '" + options.filter + "')");

    // The integrator alone.
    std::vector<double> chain_moduli;
    for (double k : moduli) chain_moduli.push_back(k == 0 ? shipped.stretch_N_m : k);
    std::vector<double> chain_steps(std::begin(steps_s), std::end(steps_s));
    for (int i = 0; i <= 30; ++i) chain_steps.push_back(1e-5 * std::pow(25000.0, i / 30.0));  // 10 us .. 0.25 s
    std::sort(chain_steps.begin(), chain_steps.end());
    chain_steps.erase(std::unique(chain_steps.begin(), chain_steps.end(),
                                  [](double a, double b) { return std::abs(a - b) <= 1e-9 * b; }),
                      chain_steps.end());
    std::vector<ChainCase> chain_cases;
    for (double k : chain_moduli)
        for (double h : chain_steps) chain_cases.push_back({k, h, run_chain(chain, k, h)});

    // ---- Summary figures, per integrator.
    struct Counts {
        int auto_cases = 0, auto_diverged = 0, auto_capped = 0, auto_capped_diverged = 0, one_cases = 0, one_diverged = 0;
    };
    constexpr ClothIntegrator integrators[] = {ClothIntegrator::shipped, ClothIntegrator::paper};
    Counts counts[2];
    bool includes_default = false;
    for (const Case& c : cases) {
        includes_default = includes_default || (c.default_material && c.auto_substeps);
        Counts& n = counts[c.integrator == ClothIntegrator::paper ? 1 : 0];
        if (c.auto_substeps) {
            ++n.auto_cases;
            if (c.capped) {
                ++n.auto_capped;
                n.auto_capped_diverged += c.divergence.diverged ? 1 : 0;
            } else if (c.divergence.diverged) {
                ++n.auto_diverged;
            }
        } else {
            ++n.one_cases;
            n.one_diverged += c.divergence.diverged ? 1 : 0;
        }
    }
    // Does the stiffness change the result? The skirt's strain p99 on the walk at 1/60 s with
    // automatic substeps, at the softest and the stiffest modulus.
    const auto walk_p99 = [&](ClothIntegrator integrator, double k) {
        for (const Case& c : cases)
            if (c.integrator == integrator && c.garment == GarmentType::skirt && c.motion == Motion::walk && c.auto_substeps &&
                !c.default_material && c.k_N_m == k && step_label(c.frame_dt_s) == "1/60")
                return c.strain_p99;
        return double(NAN);
    };

    nlohmann::json json;
    json["includes_default_material"] = includes_default;
    json["default_material"] = {{"stretch_N_m", shipped.stretch_N_m},
                                {"areal_density_kg_m2", shipped.areal_density_kg_m2},
                                {"strain_limit", shipped.strain_limit},
                                {"iterations", shipped.iterations}};
    json["limits"] = {{"reach_factor", base_limits.reach_factor},
                      {"energy_growth", base_limits.energy_growth},
                      {"energy_floor", "0.5 x garment mass x (1 m/s)^2"},
                      {"substep_cap", ClothSolverSettings{}.max_substeps},
                      {"paper_stability_substep_cap", ClothSolverSettings{}.max_stability_substeps}};
    json["cases"] = nlohmann::json::array();
    for (const Case& c : cases)
        json["cases"].push_back({{"name", c.name},
                                 {"integrator", cloth_integrator_name(c.integrator)},
                                 {"warp_solve", c.integrator == ClothIntegrator::shipped && options.warp_solve == WarpSolve::lines
                                                    ? "lines" : "rounds"},
                                 {"garment", garment_type_name(c.garment)},
                                 {"motion", motion_name(c.motion)},
                                 {"auto_substeps", c.auto_substeps},
                                 {"k_N_m", c.k_N_m},
                                 {"default_material", c.default_material},
                                 {"h_s", c.frame_dt_s},
                                 {"substeps_mean", c.mean_substeps},
                                 {"capped", c.capped},
                                 {"diverged", c.divergence.diverged},
                                 {"reason", c.divergence.reason},
                                 {"outcome", outcome(c)},
                                 {"strain_max", c.strain_max},
                                 {"strain_p99", std::isfinite(c.strain_p99) ? nlohmann::json(c.strain_p99) : nlohmann::json()},
                                 {"penetration_m", c.penetration_m},
                                 {"worst_reach_ratio", c.worst_reach},
                                 {"body_speed_m_s", c.body_speed_m_s},
                                 {"energy_peak_J", c.energy_peak_J}});
    for (const ClothIntegrator integrator : integrators) {
        const Counts& n = counts[integrator == ClothIntegrator::paper ? 1 : 0];
        const double soft = walk_p99(integrator, moduli[0]), stiff = walk_p99(integrator, moduli[std::size(moduli) - 1]);
        json["summary"][cloth_integrator_name(integrator)] = {
            {"auto_cases", n.auto_cases},
            {"auto_diverged_below_cap", n.auto_diverged},
            {"auto_capped", n.auto_capped},
            {"auto_capped_diverged", n.auto_capped_diverged},
            {"one_substep_cases", n.one_cases},
            {"one_substep_diverged", n.one_diverged},
            {"skirt_walk_strain_p99_k10", std::isfinite(soft) ? nlohmann::json(soft) : nlohmann::json()},
            {"skirt_walk_strain_p99_k1e6", std::isfinite(stiff) ? nlohmann::json(stiff) : nlohmann::json()}};
    }
    nlohmann::json explicit_json;
    explicit_json["chain"] = {{"particles", chain.particles}, {"rest_m", chain.rest_m}, {"particle_mass_kg", chain.mass_kg},
                              {"drag_N_s_m", chain.drag_N_s_m}};
    explicit_json["cases"] = nlohmann::json::array();
    for (const ChainCase& c : chain_cases)
        explicit_json["cases"].push_back({{"k_N_m", c.k_N_m}, {"h_s", c.h_s}, {"diverged", c.divergence.diverged},
                                          {"reason", c.divergence.reason}});

    Report report("Stability on stiff and extreme cases (`stability`)", options, machine);
    report.paragraph(
        "The walking default avatar wears the default skirt (" + std::to_string(skirt_particles) + " particles) or dress (" +
        std::to_string(dress_particles) + "). Matrix: stretch modulus k {10, 100, 1000, the shipped material (" +
        k_label(shipped.stretch_N_m) + " N/m, cotton, every other field as shipped), 1e4, 1e5, 1e6} N/m (the dress: "
        "{10, shipped, 1e6}, to keep the run within minutes) x fixed step h {1/240, 1/60, 1/15, 1/4} s (one frame per "
        "step) x motion x garment, with the cloth's automatic substeps and with one substep per step. Motions: walk; "
        "run (the walk clip at 2.5x speed); spin (turned at 30 rad/s about the vertical); teleport (moved 100 m at a "
        "third of the run); 10x time scale; sudden stop (carried forward at 5 m/s, then stopped dead with the "
        "animation paused at a third of the run). Each case runs max(" + std::to_string(min_frames) + " steps, " +
        fixed(run_s, 2) + " s) from " + fixed(options.start_s, 2) + " s into the walk (`--start`), the same whichever cases ran before it." +
        (options.warp_solve == WarpSolve::lines ? " The shipped integrator's warp lines are solved directly (`--warp-solve lines`)." : ""));
    report.paragraph(
        "**Divergence** (bench/stability_bench.hpp): a non-finite value (the cloth resets such a garment and counts "
        "it); a particle farther from its pin (the nearest along the springs) than " + fixed(1 + base_limits.reach_factor, 1) +
        "x the rest length of the longest spring path from that pin (its warp line: how far the garment reaches from "
        "there; a particle near the pins is allowed the same distance, so the push-outs of the collision cannot trip "
        "it); or energy growth: the kinetic energy's peak in "
        "the last third of the run above " + fixed(base_limits.energy_growth, 0) + "x its peak in the first two "
        "thirds and above that of the garment moving at 1 m/s. **Quality**, measured after every whole frame "
        "(systems/cloth/garment_quality.hpp, springs with a free end): strain max and p99 over the run, deepest "
        "free particle inside the body. **Capped**: with automatic substeps, the rule asked for the cap (" +
        std::to_string(ClothSolverSettings{}.max_substeps) + " substeps) or more on some frame, so the automatic "
        "substeps could not follow it; such a case is counted apart, whatever happened.");

    report.paragraph(
        "**Two integrators** (docs/cloth.md \"Two integrators\"): the shipped solver (eq. 2 without its spring term, the "
        "springs as compliant constraints, the limits and contact repair) and the paper's scheme as written (eq. 2 with "
        "its spring forces, explicit; layer 2 placed from layer 1; Provot's limit after the step; each particle out of "
        "the ellipsoids with its normal velocity removed). The paper's automatic substeps come from the explicit "
        "springs' stability bound (systems/cloth/integrator.hpp spring_step_limit_s) and are capped only at " +
        std::to_string(ClothSolverSettings{}.max_stability_substeps) + " (ClothSolverSettings::max_stability_substeps); "
        "it runs on the skirt only (the dress at 1e6 N/m would take hours).");
    if (!options.filter.empty())
        report.paragraph("Only the cases whose name matches --filter '" + options.filter + "' ran (" + std::to_string(cases.size()) +
                         " cases); the summary counts those.");

    report.heading("Summary");
    std::vector<Target> targets;
    for (const ClothIntegrator integrator : integrators) {
        const Counts& n = counts[integrator == ClothIntegrator::paper ? 1 : 0];
        const std::string name = cloth_integrator_name(integrator);
        const double soft = walk_p99(integrator, moduli[0]), stiff = walk_p99(integrator, moduli[std::size(moduli) - 1]);
        report.paragraph("**" + name + "**: automatic substeps: **" + std::to_string(n.auto_diverged) + "** of " +
                         std::to_string(n.auto_cases) + " cases diverged with the cap never reached; " +
                         std::to_string(n.auto_capped) + " cases reached the cap (" + std::to_string(n.auto_capped_diverged) +
                         " of them diverged). One substep per step: **" + std::to_string(n.one_diverged) + "** of " +
                         std::to_string(n.one_cases) + " diverged. The skirt's strain p99 on the walk (h = 1/60 s, automatic "
                         "substeps): " + fixed(100 * soft, 2) + " % at k = 10 N/m, " + fixed(100 * stiff, 2) + " % at 1e6 N/m.");
        targets.push_back(upper_bound_target(name + ": cases diverged with automatic substeps below the cap", n.auto_diverged, 0, "", 0));
    }
    report.targets(targets);

    std::vector<std::vector<std::string>> summary;
    for (const ClothIntegrator integrator : integrators)
    for (GarmentType garment : {GarmentType::skirt, GarmentType::dress})
        for (bool automatic : {true, false})
            for (double k : modulus_set(garment)) {
                std::vector<std::string> row;
                std::string k_text;
                for (double dt : steps_s) {
                    int total = 0, diverged = 0, capped = 0;
                    double worst_p99 = 0, substeps = 0;
                    for (const Case& c : cases)
                        if (c.integrator == integrator && c.garment == garment && c.auto_substeps == automatic &&
                            c.default_material == (k == 0) &&
                            (k == 0 || c.k_N_m == k) && c.frame_dt_s == dt) {
                            k_text = k_label(c.k_N_m) + (c.default_material ? " (shipped)" : "");
                            ++total;
                            diverged += c.divergence.diverged ? 1 : 0;
                            capped += c.capped ? 1 : 0;
                            if (std::isfinite(c.strain_p99)) worst_p99 = std::max(worst_p99, c.strain_p99);
                            substeps += c.mean_substeps;
                        }
                    row.push_back(std::to_string(diverged) + " / " + std::to_string(capped) + " / " + std::to_string(total) +
                                  ", p99 " + fixed(100 * worst_p99, 1) + " %" +
                                  (automatic ? ", " + fixed(substeps / std::max(1, total), 1) + " sub" : ""));
                }
                if (k_text.empty()) continue;  // (the paper's integrator: no dress)
                row.insert(row.begin(), {cloth_integrator_name(integrator), garment_type_name(garment), automatic ? "auto" : "1", k_text});
                summary.push_back(row);
            }
    report.paragraph("Per cell: diverged / capped / motions run, the worst strain p99 of the cell's motions, and with "
                     "automatic substeps the mean substeps per step:");
    report.table({"integrator", "garment", "substeps", "k (N/m)", "h = 1/240 s", "h = 1/60 s", "h = 1/15 s", "h = 1/4 s"}, summary);

    report.heading("The shipped material, automatic substeps");
    std::vector<std::vector<std::string>> shipped_rows;
    for (const Case& c : cases)
        if (c.default_material && c.auto_substeps)
            shipped_rows.push_back({cloth_integrator_name(c.integrator), garment_type_name(c.garment), motion_name(c.motion), step_label(c.frame_dt_s),
                                    fixed(c.mean_substeps, 2), outcome(c), fixed(100 * c.strain_max, 1),
                                    fixed(100 * c.strain_p99, 1), fixed(1000 * c.penetration_m, 2), fixed(c.worst_reach, 2),
                                    c.divergence.reason});
    report.table({"integrator", "garment", "motion", "h (s)", "substeps / step", "outcome", "strain max (%)", "strain p99 (%)",
                  "penetration (mm)", "reach ratio", "reason"},
                 shipped_rows);

    report.heading("Diverged or capped with automatic substeps");
    std::vector<std::vector<std::string>> flagged;
    for (const Case& c : cases)
        if (c.auto_substeps && (c.capped || c.divergence.diverged))
            flagged.push_back({c.name, outcome(c), fixed(c.mean_substeps, 1), std::to_string(c.capped_frames),
                               fixed(100 * c.strain_p99, 1), c.divergence.reason});
    if (flagged.empty())
        report.paragraph("None.");
    else
        report.table({"case", "outcome", "substeps / step", "frames at the cap", "strain p99 (%)", "reason"}, flagged);

    report.heading("The explicit limit of the integrator alone");
    report.paragraph(
        "The shipped solver solves its springs as constraints in compliance form (systems/cloth/constraints.hpp), stable at any "
        "stiffness; its explicit part is eq. 2 without the springs. To map where the paper's explicit scheme breaks, a "
        "hanging chain of " + std::to_string(chain.particles) + " particles (the skirt's warp line: median free-particle "
        "mass " + fixed(1e6 * chain.mass_kg, 1) + " mg, median warp rest length " + fixed(1000 * chain.rest_m, 1) +
        " mm, drag " + fixed(1e3 * chain.drag_N_s_m, 3) + " mN s/m per particle) hangs from its pinned top particle "
        "with Hooke springs of stiffness k as explicit forces, and is stepped by symplectic Euler through the cloth's "
        "own prediction (predict_particles of systems/cloth/integrator.hpp adds gravity and drag and moves the "
        "particles; the spring impulse h F is added to the velocities before it). No constraint, no Provot limit, no "
        "collision. For a square cell of the sheet, a spring's k equals the stretch modulus. Released at rest length, "
        "it runs max(" + fixed(chain_run_s, 1) + " s, " + std::to_string(chain_min_steps) + " steps); divergence is "
        "judged as above. The bound is that of the linearised chain, h < 2 / sqrt(lambda_max(M^-1 K)); a single "
        "spring to a fixed point gives 2 sqrt(m/k).");
    std::vector<std::vector<std::string>> bound_rows;
    PlotData stable_points{"stable", {}}, diverged_points{"diverged", {}}, bound_line{"bound", {}};
    for (double k : chain_moduli) {
        double largest_ok = 0, smallest_bad = INFINITY;
        std::vector<std::string> frame_steps;
        for (const ChainCase& c : chain_cases) {
            if (c.k_N_m != k) continue;
            if (c.divergence.diverged)
                smallest_bad = std::min(smallest_bad, c.h_s);
            else if (c.h_s < smallest_bad)
                largest_ok = std::max(largest_ok, c.h_s);
            (c.divergence.diverged ? diverged_points : stable_points).rows.push_back({k, 1000 * c.h_s});
            for (double dt : steps_s)
                if (std::abs(c.h_s - dt) <= 1e-9 * dt) frame_steps.push_back(c.divergence.diverged ? "**diverged**" : "ok");
        }
        const double bound = chain_bound_s(chain, k);
        bound_line.rows.push_back({k, 1000 * bound});
        explicit_json["bounds"].push_back({{"k_N_m", k}, {"single_spring_s", 2 * std::sqrt(chain.mass_kg / k)},
                                           {"chain_s", bound}, {"largest_stable_h_s", largest_ok},
                                           {"smallest_diverged_h_s", std::isfinite(smallest_bad) ? nlohmann::json(smallest_bad) : nlohmann::json()}});
        std::vector<std::string> row{k_label(k) + (k == shipped.stretch_N_m ? " (shipped)" : ""),
                                     fixed(2000 * std::sqrt(chain.mass_kg / k), 4), fixed(1000 * bound, 4),
                                     fixed(1000 * largest_ok, 4), std::isfinite(smallest_bad) ? fixed(1000 * smallest_bad, 4) : "none"};
        row.insert(row.end(), frame_steps.begin(), frame_steps.end());
        bound_rows.push_back(row);
    }
    report.table({"k (N/m)", "2 sqrt(m/k) (ms)", "chain bound (ms)", "largest h without divergence (ms)",
                  "smallest h that diverged (ms)", "h = 1/240 s", "h = 1/60 s", "h = 1/15 s", "h = 1/4 s"},
                 bound_rows);
    report.paragraph("Steps scanned: the four frame steps and 31 steps spaced evenly in log from 10 us to 0.25 s (" +
                     std::to_string(chain_steps.size()) + " in all); "
                     "\"largest h without divergence\" is the largest step below the smallest that diverged.");
    if (stable_points.rows.empty()) stable_points.rows.push_back({NAN, NAN});
    if (diverged_points.rows.empty()) diverged_points.rows.push_back({NAN, NAN});
    const std::string script =
        "set title 'Hanging chain, explicit springs through the cloth prediction: where symplectic Euler diverges'\n"
        "set xlabel 'spring stiffness k (N/m)'\nset ylabel 'step h (ms)'\nset logscale xy\nset grid\nset key outside right\n"
        "plot $stable using 1:2 with points pt 7 ps 1 lc rgb '#30a050' title 'not diverged', "
        "$diverged using 1:2 with points pt 2 ps 1.2 lw 2 lc rgb '#c03020' title 'diverged', "
        "$bound using 1:2 with lines lw 2 lc rgb '#3060c0' title 'chain bound 2/sqrt(lambda max)'\n";
    report.plot("stability.png", "Explicit limit: step against stiffness", {stable_points, diverged_points, bound_line}, script,
                1000, 560);

    json["explicit_limit"] = explicit_json;
    return finish(report, options, json);
}

}  // namespace drape::bench
