// `drape bench render`: off-screen rendering cost at 1280x720.
//
// The walking default avatar in the skirt (and in the dress) is simulated for a while with
// the render system in the schedule, then the same state is drawn repeatedly through the
// render system's path (time_render_frames: camera follow, draw, MSAA resolve, wait for
// the GPU), without and with reading the frame back to the CPU as a video export does.
// Off-screen rendering goes through Mesa; on a machine without a GPU that is llvmpipe,
// which rasterises on the CPU cores the simulation also uses.
#include <algorithm>
#include <chrono>

#include "bench/probe.hpp"
#include "bench/report.hpp"
#include "bench/world.hpp"
#ifdef DRAPE_HAVE_RENDER
#include "drape/engine/render/renderer.hpp"
#include "drape/systems/render_system.hpp"
#endif

namespace drape::bench {

namespace {

constexpr double frame_dt_s = 1.0 / 60.0;
constexpr int settle_frames = 60;
constexpr int timed_frames = 30;

struct Row {
    std::string scene;
    std::size_t particles = 0;
    double system_ms = 0;      ///< The render system inside a tick (profiler).
    double draw_ms = 0;        ///< time_render_frames without readback.
    double readback_ms = 0;    ///< With readback.
    double frame_ms = 0;       ///< Whole tick with rendering.
};

}  // namespace

Result<void> run_render(const BenchOptions& options) {
#ifndef DRAPE_HAVE_RENDER
    (void)options;
    return fail("render: this build has no render module (DRAPE_RENDER=OFF)");
#else
    const Machine machine = describe_machine();
    std::vector<Row> rows;
    std::string renderer_text;
    for (GarmentType garment : {GarmentType::skirt, GarmentType::dress}) {
        std::vector<double> system, draw, readback, frame;
        Row row;
        row.scene = std::string("walking avatar in the default ") + garment_type_name(garment);
        for (int run = 0; run < options.runs; ++run) {
            WorldSpec spec;
            spec.garment = garment;
            spec.render = true;
            spec.threads = options.threads;
            auto world = build_bench_world(spec);
            if (!world) return fail("render: " + world.error().message);
            if (!world->renderer) return fail("render: the world has no renderer");
            for (int f = 0; f < settle_frames; ++f)
                if (auto ok = step_world(*world, frame_dt_s); !ok) return fail("render: " + ok.error().message);
            const auto& profiler = world->scheduler.profiler();
            const double render_before = profiler.stats("render").total_ms;
            // A tick is only done when its frame is: GL queues the draw, and llvmpipe rasterises it
            // on the same cores afterwards, so each timed tick waits for the frame to finish.
            std::vector<double> ticks_ms;
            for (int f = 0; f < timed_frames; ++f) {
                const auto start = std::chrono::steady_clock::now();
                if (auto ok = step_world(*world, frame_dt_s); !ok) return fail("render: " + ok.error().message);
                world->renderer->finish();
                ticks_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
            }
            system.push_back((profiler.stats("render").total_ms - render_before) / timed_frames);
            frame.push_back(median(ticks_ms));
            auto no_readback = time_render_frames(*world->renderer, world->registry, timed_frames, false);
            if (!no_readback) return fail("render: " + no_readback.error().message);
            auto with_readback = time_render_frames(*world->renderer, world->registry, timed_frames, true);
            if (!with_readback) return fail("render: " + with_readback.error().message);
            draw.push_back(median(*no_readback));
            readback.push_back(median(*with_readback));
            row.particles = static_cast<std::size_t>(first_garment(*world).state.x.cols());
            const RendererInfo& info = world->renderer->info();
            renderer_text = info.gl_renderer + " (" + info.gl_version + "), platform " + info.platform + ", MSAA " +
                            std::to_string(info.msaa_samples) + "x";
        }
        row.system_ms = median(system);
        row.draw_ms = median(draw);
        row.readback_ms = median(readback);
        row.frame_ms = median(frame);
        rows.push_back(row);
    }

    nlohmann::json json;
    json["width"] = 1280;
    json["height"] = 720;
    json["renderer"] = renderer_text;
    json["rows"] = nlohmann::json::array();
    for (const auto& r : rows)
        json["rows"].push_back({{"scene", r.scene}, {"particles", r.particles}, {"render_system_ms", r.system_ms},
                                {"draw_ms", r.draw_ms}, {"draw_readback_ms", r.readback_ms}, {"frame_ms", r.frame_ms}});

    Report report("Off-screen rendering at 1280x720 (`render`)", options, machine);
    report.paragraph(
        "Renderer: " + renderer_text + ". Each run builds the scene with an off-screen 1280x720 renderer, simulates " +
        std::to_string(settle_frames) + " frames, then times " + std::to_string(timed_frames) + " ticks with the "
        "render system in the schedule (render system time from the frame profiler, which stops when the draw "
        "calls are queued; whole tick = wall time of simulation + rendering until the frame is finished), and " + std::to_string(timed_frames) + " redraws of the same state through the render "
        "system's path (time_render_frames: camera follow, draw, resolve, wait until the frame is finished) without "
        "and with reading the pixels back. Figures are medians over frames, then over runs. On a machine without a "
        "GPU, Mesa's llvmpipe rasterises on the same CPU cores the simulation uses.");
    std::vector<std::vector<std::string>> table;
    for (const auto& r : rows)
        table.push_back({r.scene, std::to_string(r.particles), fixed(r.system_ms, 2), fixed(r.draw_ms, 2),
                         fixed(r.readback_ms, 2), fixed(r.frame_ms, 2), fixed(1000.0 / std::max(1e-9, r.frame_ms), 1)});
    report.table({"scene", "garment particles", "render system ms", "draw ms", "draw + readback ms", "whole tick ms", "fps"},
                 table);
    report.heading("Frame budget");
    std::vector<Target> targets;
    // The sample scene is the skirt; the dress row is there to show how the cost grows.
    targets.push_back(upper_bound_target(rows.front().scene + ": whole tick with rendering (60 fps)", rows.front().frame_ms,
                                         1000.0 / 60.0, "ms", 2));
    report.paragraph("Target: the sample scene (the skirt) at 60 fps or better, i.e. the whole tick, waiting for the "
                     "frame to be finished, within 16.67 ms. The dress is shown for reference.");
    report.targets(targets);

    std::vector<PlotData> data{{"r", {}}};
    for (std::size_t i = 0; i < rows.size(); ++i)
        data[0].rows.push_back({static_cast<double>(i), rows[i].system_ms, rows[i].draw_ms, rows[i].readback_ms, rows[i].frame_ms});
    const std::string script =
        "set title 'Off-screen 1280x720 (" + renderer_text + ")'\nset style data histograms\n"
        "set style histogram clustered gap 1\nset style fill solid 0.8 border -1\nset ylabel 'ms per frame'\n"
        "set grid ytics\nset yrange [0:*]\nset key top left\nset xtics ('skirt' 0, 'dress' 1)\n"
        "plot $r using 2 title 'render system' lc rgb '#3060c0', '' using 3 title 'draw' lc rgb '#60a0e0', "
        "'' using 4 title 'draw + readback' lc rgb '#c04030', '' using 5 title 'whole tick' lc rgb '#30a050'\n";
    report.plot("render.png", "Rendering ms per frame", data, script);

    return finish(report, options, json);
#endif
}

}  // namespace drape::bench
