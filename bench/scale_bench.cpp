// `drape bench scale`: how the cost grows with garment size, walker count and threads.
//
// Each configuration builds one world, steps 20 frames to settle, then measures `runs`
// windows of 30 frames; a figure is the median over windows of the per-frame mean in a
// window. Times come from the frame profiler: body = animation + skinning phases (the
// colliders; the mesh is skinned only when drawing, and these worlds are headless), cloth =
// integration + constraint systems, collision = collision system, frame = the whole tick.
// Walkers start at different phases of the walk. Threads are limited per world with
// tbb::global_control (the world's solver.threads). For 100 and 200 walkers the report
// also lists every system and section of the frame profile.
#include <algorithm>
#include <map>

#include "bench/probe.hpp"
#include "bench/report.hpp"
#include "bench/world.hpp"

namespace drape::bench {

namespace {

constexpr double frame_dt_s = 1.0 / 60.0;
constexpr int settle_frames = 20;
constexpr int window_frames = 30;
constexpr double phase_step_s = 0.37;  // walker i starts i x this into the walk (1.1 s): spread phases

// Total ms of every profiler slot (systems and sections), by name.
std::map<std::string, double> slot_totals(const Scheduler& scheduler) {
    std::map<std::string, double> out;
    for (const SystemStats& s : scheduler.profiler().stats()) out[s.name] = s.total_ms;
    return out;
}

struct Point {
    std::string label;
    GarmentType garment;
    int walkers, threads;
    std::size_t particles = 0;    ///< Per garment.
    double body_ms = 0, cloth_ms = 0, collide_ms = 0, garment_ms = 0, frame_ms = 0;
    double substeps = 0;
    double animation_ms = 0, colliders_ms = 0;
    std::vector<std::pair<std::string, double>> systems{};  ///< Every system and section, ms per frame, profile order.

    [[nodiscard]] double body_us_per_walker() const { return walkers ? 1000.0 * body_ms / walkers : 0; }

    [[nodiscard]] double us_per_particle() const {
        return particles ? 1000.0 * garment_ms / static_cast<double>(particles * static_cast<std::size_t>(walkers)) : 0;
    }
};

Result<Point> measure(Point p, int particles, int windows) {
    WorldSpec spec;
    spec.walkers = p.walkers;
    spec.garment = p.garment;
    spec.particles = particles;
    spec.threads = p.threads;
    spec.phase_step_s = phase_step_s;
    auto world = build_bench_world(spec);
    if (!world) return fail(world.error().message);
    for (int f = 0; f < settle_frames; ++f)
        if (auto ok = step_world(*world, frame_dt_s); !ok) return fail(ok.error().message);
    std::vector<double> body, animation, colliders, cloth, collide, garment, frame, substeps;
    std::map<std::string, std::vector<double>> systems;
    for (int w = 0; w < windows; ++w) {
        const ClothSystemTime start = cloth_system_totals(world->scheduler);
        const std::map<std::string, double> slots_start = slot_totals(world->scheduler);
        double sub = 0;
        for (int f = 0; f < window_frames; ++f) {
            if (auto ok = step_world(*world, frame_dt_s); !ok) return fail(ok.error().message);
            sub += first_garment(*world).counters.substeps;
        }
        const ClothSystemTime t = per_frame(cloth_system_totals(world->scheduler), start, window_frames);
        body.push_back(t.animation_ms + t.skinning_ms);
        animation.push_back(t.animation_ms);
        colliders.push_back(t.skinning_ms);
        for (const auto& [name, total] : slot_totals(world->scheduler))
            systems[name].push_back((total - slots_start.at(name)) / window_frames);
        cloth.push_back(t.integrate_ms);
        collide.push_back(t.collide_ms);
        garment.push_back(t.garment_ms);
        frame.push_back(t.frame_ms);
        substeps.push_back(sub / window_frames);
    }
    p.particles = static_cast<std::size_t>(first_garment(*world).state.x.cols());
    p.body_ms = median(body);
    p.cloth_ms = median(cloth);
    p.collide_ms = median(collide);
    p.garment_ms = median(garment);
    p.frame_ms = median(frame);
    p.substeps = median(substeps);
    p.animation_ms = median(animation);
    p.colliders_ms = median(colliders);
    for (const SystemStats& s : world->scheduler.profiler().stats())
        p.systems.emplace_back(s.parent.empty() ? s.name : s.parent + " / " + s.name, median(systems[s.name]));
    return p;
}

std::vector<std::string> row_of(const Point& p) {
    return {p.label,           std::to_string(p.walkers), std::to_string(p.threads),   std::to_string(p.particles),
            fixed(p.body_ms, 3), fixed(p.cloth_ms, 3),    fixed(p.collide_ms, 3),      fixed(p.garment_ms, 3),
            fixed(p.frame_ms, 3), fixed(p.us_per_particle(), 4), fixed(p.substeps, 2)};
}

std::vector<std::string> walker_row_of(const Point& p) {
    return {p.label,
            std::to_string(p.walkers),
            std::to_string(p.threads),
            fixed(p.animation_ms, 3),
            fixed(p.colliders_ms, 3),
            fixed(p.body_us_per_walker(), 2),
            fixed(p.cloth_ms, 3),
            fixed(p.collide_ms, 3),
            fixed(p.garment_ms, 3),
            fixed(p.frame_ms, 3),
            fixed(p.us_per_particle(), 4),
            fixed(p.substeps, 2)};
}

}  // namespace

Result<void> run_scale(const BenchOptions& options) {
    const Machine machine = describe_machine();
    const int windows = std::max(1, options.runs);
    std::vector<Point> sizes, walkers;
    for (int threads : {1, 2}) {
        for (int particles : {837, 3000, 10000, 30000, 100000}) {
            auto p = measure({"skirt " + std::to_string(particles), GarmentType::skirt, 1, threads}, particles, windows);
            if (!p) return fail("scale: " + p.error().message);
            sizes.push_back(*p);
        }
        auto dress = measure({"dress (default)", GarmentType::dress, 1, threads}, 0, windows);
        if (!dress) return fail("scale: " + dress.error().message);
        sizes.push_back(*dress);
        for (int count : {1, 10, 50, 100, 200}) {
            auto p = measure({"walkers " + std::to_string(count), GarmentType::skirt, count, threads}, 0, windows);
            if (!p) return fail("scale: " + p.error().message);
            walkers.push_back(*p);
        }
    }

    auto find = [](const std::vector<Point>& points, const std::string& label, int threads) -> const Point* {
        for (const auto& p : points)
            if (p.label == label && p.threads == threads) return &p;
        return nullptr;
    };
    const Point* dress1 = find(sizes, "dress (default)", 1);
    const Point* dress2 = find(sizes, "dress (default)", 2);
    const Point* hundred2 = find(walkers, "walkers 100", 2);
    const Point* two_hundred2 = find(walkers, "walkers 200", 2);

    nlohmann::json json;
    auto to_json = [](const Point& p) {
        return nlohmann::json{{"label", p.label},         {"garment", garment_type_name(p.garment)},
                              {"walkers", p.walkers},     {"threads", p.threads},
                              {"particles", p.particles}, {"body_ms", p.body_ms},
                              {"cloth_ms", p.cloth_ms},   {"collide_ms", p.collide_ms},
                              {"garment_ms", p.garment_ms}, {"frame_ms", p.frame_ms},
                              {"us_per_particle_frame", p.us_per_particle()}, {"substeps", p.substeps},
                              {"animation_ms", p.animation_ms}, {"colliders_ms", p.colliders_ms},
                              {"body_us_per_walker", p.body_us_per_walker()}, {"systems_ms", [&] {
                                   nlohmann::json systems = nlohmann::json::object();
                                   for (const auto& [name, ms] : p.systems) systems[name] = ms;
                                   return systems;
                               }()}};
    };
    json["sizes"] = nlohmann::json::array();
    json["walkers"] = nlohmann::json::array();
    for (const auto& p : sizes) json["sizes"].push_back(to_json(p));
    for (const auto& p : walkers) json["walkers"].push_back(to_json(p));

    Report report("Scaling with garment size, walkers and threads (`scale`)", options, machine);
    report.paragraph(
        "The default avatar walking in place at 60 fps, headless (no rendering, so no mesh skinning: the cloth "
        "follows the bones). Garment size: one walker in a skirt of 837 to 100,000 particles "
        "(the builder's target count) and in the default dress. Walkers: 1 to 200 characters, each in the default "
        "skirt, 1.5 m apart, walker i starting " + fixed(phase_step_s, 2) + " s x i into the walk (different phases). "
        "Each configuration: one world, " + std::to_string(settle_frames) + " frames to settle, "
        "then " + std::to_string(windows) + " windows of " + std::to_string(window_frames) + " frames; figures are "
        "the median over windows of the per-frame mean. body = animation + collider systems (us / walker: body time "
        "over the walkers); cloth = "
        "integration + constraint systems; collision = collision system; garment = cloth + collision (every "
        "simulation-phase system); frame = the whole tick. us/particle = garment time per particle per frame. "
        "Threads: the world's solver.threads (tbb::global_control); the machine has " +
        std::to_string(machine.logical_cpus) + " logical CPUs shared with other work, so 2-thread figures depend "
        "on what else ran.");
    const std::vector<std::string> header{"configuration", "walkers", "threads", "particles each", "body ms", "cloth ms",
                                          "collision ms", "garment ms", "frame ms", "us / particle", "substeps"};
    report.heading("Garment size");
    std::vector<std::vector<std::string>> rows;
    for (const auto& p : sizes) rows.push_back(row_of(p));
    report.table(header, rows);
    report.heading("Walkers");
    rows.clear();
    for (const auto& p : walkers) rows.push_back(walker_row_of(p));
    report.table({"configuration", "walkers", "threads", "animation ms", "colliders ms", "body us / walker", "cloth ms",
                  "collision ms", "garment ms", "frame ms", "us / particle", "substeps"},
                 rows);

    report.heading("Systems for 100 and 200 walkers");
    report.paragraph("Every system of the frame profile (a section of a system as system / section), ms per frame: the median "
                     "over windows of the per-frame mean. A system that was skipped or is absent shows 0.");
    std::vector<const Point*> crowd;
    for (const char* label : {"walkers 100", "walkers 200"})
        for (int threads : {1, 2})
            if (const Point* p = find(walkers, label, threads)) crowd.push_back(p);
    if (!crowd.empty()) {
        std::vector<std::string> system_header{"system"};
        for (const Point* p : crowd)
            system_header.push_back(std::to_string(p->walkers) + " walkers, " + std::to_string(p->threads) +
                                    (p->threads == 1 ? " thread" : " threads"));
        rows.clear();
        for (std::size_t k = 0; k < crowd.front()->systems.size(); ++k) {
            const std::string& name = crowd.front()->systems[k].first;
            std::vector<std::string> row{name};
            for (const Point* p : crowd) {
                double ms = 0;
                for (const auto& [n, v] : p->systems)
                    if (n == name) ms = v;
                row.push_back(fixed(ms, 3));
            }
            rows.push_back(std::move(row));
        }
        std::vector<std::string> frame_row{"whole frame"};
        for (const Point* p : crowd) frame_row.push_back(fixed(p->frame_ms, 3));
        rows.push_back(std::move(frame_row));
        report.table(system_header, rows);
    }

    report.heading("Targets");
    std::vector<Target> targets;
    if (dress1) targets.push_back(upper_bound_target("10,000-particle dress, garment ms per frame, 1 thread", dress1->garment_ms, 1.0, "ms"));
    if (dress2) targets.push_back(upper_bound_target("10,000-particle dress, garment ms per frame, 2 threads", dress2->garment_ms, 1.0, "ms"));
    if (hundred2) {
        targets.push_back(upper_bound_target("100 skirted walkers, whole frame on two threads", hundred2->frame_ms, 8.0, "ms", 2));
        targets.push_back(upper_bound_target("100 walkers, headless body work (animation + colliders) per walker, two threads",
                                             hundred2->body_ms / hundred2->walkers, 0.02, "ms", 4));
    }
    if (two_hundred2) {
        targets.push_back(upper_bound_target("200 skirted walkers, whole frame on two threads (60 fps)", two_hundred2->frame_ms,
                                             1000.0 / 60.0, "ms", 2));
        targets.push_back(upper_bound_target("200 walkers, headless body work (animation + colliders) per walker, two threads",
                                             two_hundred2->body_ms / two_hundred2->walkers, 0.02, "ms", 4));
    }
    report.targets(targets);

    // Plot: us per particle against size, and frame ms against walkers, for 1 and 2 threads.
    std::vector<PlotData> data;
    for (int threads : {1, 2}) {
        PlotData s{"size" + std::to_string(threads), {}}, w{"walk" + std::to_string(threads), {}};
        for (const auto& p : sizes)
            if (p.threads == threads && p.garment == GarmentType::skirt)
                s.rows.push_back({static_cast<double>(p.particles), p.us_per_particle(), 1000.0 * p.cloth_ms / p.particles,
                                  1000.0 * p.collide_ms / p.particles});
        for (const auto& p : walkers)
            if (p.threads == threads) w.rows.push_back({static_cast<double>(p.walkers), p.frame_ms, p.body_ms, p.garment_ms});
        data.push_back(s);
        data.push_back(w);
    }
    const std::string script =
        "set multiplot layout 1,2\nset grid\nset logscale x\nset key top left\n"
        "set title 'Garment size (one skirt)'\nset xlabel 'particles'\nset ylabel 'us per particle per frame'\n"
        "plot $size1 using 1:2 with linespoints pt 7 lc rgb '#3060c0' title 'garment, 1 thread', "
        "$size2 using 1:2 with linespoints pt 5 lc rgb '#c04030' title 'garment, 2 threads', "
        "$size1 using 1:3 with lines dt 2 lc rgb '#3060c0' title 'cloth, 1 thread', "
        "$size1 using 1:4 with lines dt 3 lc rgb '#3060c0' title 'collision, 1 thread'\n"
        "set title 'Walkers in skirts'\nset xlabel 'walkers'\nset ylabel 'ms per frame'\nset logscale y\n"
        "plot $walk1 using 1:2 with linespoints pt 7 lc rgb '#3060c0' title 'frame, 1 thread', "
        "$walk2 using 1:2 with linespoints pt 5 lc rgb '#c04030' title 'frame, 2 threads', "
        "$walk1 using 1:3 with lines dt 2 lc rgb '#3060c0' title 'body, 1 thread', "
        "$walk1 using 1:4 with lines dt 3 lc rgb '#3060c0' title 'garments, 1 thread', "
        "16.667 with lines lc rgb '#30a050' title '60 fps'\n"
        "unset multiplot\n";
    report.plot("scale.png", "Cost per particle against garment size; frame time against walkers", data, script, 1200, 500);

    return finish(report, options, json);
}

}  // namespace drape::bench
