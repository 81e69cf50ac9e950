// `drape play`: builds a scene (the sample scene by default), runs it for a number of
// frames, writes what was asked (PNG frames, a video, a trace, stats) and prints the frame
// budget and a verdict on every garment. Usage and options: docs/play.md and
// `drape play --help`.
//
// play() is a sequence of steps, each a function below: check the options, load the scene,
// apply the command-line overrides, build the world, open the outputs, run the frames,
// close the outputs, print the budget and the verdict, write the reports. Nothing is written before every
// input has been checked and the world is built; a step that fails prints one line and
// leaves nothing the run created behind (CreatedOutputs, game/output_files.hpp).
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <unistd.h>

#include "drape/engine/assets/garment_file.hpp"
#include "drape/game/commands.hpp"
#include "drape/game/contract.hpp"
#include "drape/game/frame_hud.hpp"
#include "drape/game/output_files.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/scene_file.hpp"
#include "drape/game/stats.hpp"
#include "drape/game/video.hpp"
#include "drape/game/world.hpp"

#ifdef DRAPE_HAVE_RENDER
#include "drape/engine/render/renderer.hpp"
#endif

namespace drape {

namespace {

namespace fs = std::filesystem;

struct PlayOptions {
    std::string scene, character, clip, motion, garment, model, integrator, warp_solve, pin_weights, out, video, trace, stats, size;
    std::optional<int> frames;
    std::optional<int> threads;
    std::optional<int> trace_size;
    std::optional<double> time_scale;
    double fps = 60;
    bool headless = false, window = false, overwrite = false, strict = false, hud = false;
};

// Ctrl-C stops the loop between frames, so the video, stats and trace are still complete.
volatile std::sig_atomic_t g_interrupted = 0;
void on_interrupt(int) { g_interrupted = 1; }

// Errors of this command: "drape play: --size: must be WxH ..." on stderr, exit code 1.
int report(const std::string& message) { return command_error("play", message); }

Result<std::pair<int, int>> parse_size(const std::string& text) {
    int w = 0, h = 0;
    char x = 0;
    char rest = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &rest) != 3 || (x != 'x' && x != 'X'))
        return fail("--size: must be WIDTHxHEIGHT in pixels, e.g. 1280x720, got \"" + text + "\"");
    if (w < 16 || h < 16 || w > 8192 || h > 8192)
        return fail("--size: each side must be in [16, 8192] pixels, got " + text);
    return std::pair{w, h};
}

// ---------------------------------------------------------------------------------------
// 1. Options: what needs no scene. Option ranges, NaN included, are checked by the
//    command line's validators.

/// What the options come to.
struct PlaySettings {
    std::pair<int, int> size{1280, 720};  ///< Frame size, px.
    bool headless = false;                ///< Nothing rendered (asked for, or no render module).
    bool window = false;                  ///< In an X11 window.
    bool hud = false;                     ///< The frame budget overlay drawn from the start.
};

Result<PlaySettings> check_options(const PlayOptions& o) {
    PlaySettings s;
    if (!o.size.empty()) {
        auto size = parse_size(o.size);
        if (!size) return std::unexpected(size.error());
        s.size = *size;
    }
    if (o.headless) {
        if (o.window) return fail("--headless: cannot be combined with --window (nothing is rendered)");
        if (!o.out.empty()) return fail("--headless: cannot be combined with --out (nothing is rendered)");
        if (!o.video.empty()) return fail("--headless: cannot be combined with --video (nothing is rendered)");
    }
    s.headless = o.headless;
    if (!render_available()) {
        if (o.window) return fail("--window: this build has no render module (configured with -DDRAPE_RENDER=OFF)");
        if (!o.out.empty()) return fail("--out: this build has no render module (configured with -DDRAPE_RENDER=OFF)");
        if (!o.video.empty()) return fail("--video: this build has no render module (configured with -DDRAPE_RENDER=OFF)");
        if (!s.headless) std::printf("drape play: the render module is not built (-DDRAPE_RENDER=OFF): playing headless\n");
        s.headless = true;
    }
    s.window = o.window && !s.headless;
    if (o.hud && s.headless) return fail("--hud: nothing is rendered (--headless, or no render module) to draw it on");
    s.hud = o.hud || s.window;  // in a window it starts shown (the H key hides it)
    if (o.trace_size && o.trace.empty()) return fail("--trace-size: needs --trace FILE (the trace it sizes)");
    if (!o.video.empty() && !find_ffmpeg())
        return fail("--video: ffmpeg is not installed (apt-get install ffmpeg); --out DIR writes PNG frames instead");
    if (!o.out.empty()) {
        std::error_code ec;
        if (fs::exists(o.out, ec) && !fs::is_directory(o.out, ec)) return fail("--out: " + o.out + " exists and is not a folder");
        if (!o.overwrite && fs::is_directory(o.out, ec) && !frame_files(o.out).empty())
            return fail("--out: " + o.out + " already holds frames (frame_00000.png, ...); add --overwrite to replace them");
    }
    if (!s.headless && !o.window && o.video.empty() && o.out.empty()) {  // the default output goes under out/
        std::error_code ec;
        if (fs::exists("out", ec) && !fs::is_directory("out", ec))
            return fail("out: exists and is not a folder (the default output goes there; name one with --video or --out)");
    }
    const std::array<std::pair<const char*, std::string>, 3> files{
        {{"--stats", o.stats}, {"--trace", o.trace}, {"--video", o.video}}};
    for (std::size_t i = 0; i < files.size(); ++i) {
        const auto& [name, file] = files[i];
        if (file.empty()) continue;
        std::error_code ec;
        const fs::path folder = fs::path(file).parent_path();
        if (!folder.empty() && !fs::is_directory(folder, ec))
            return fail(std::string(name) + ": folder " + folder.string() + " does not exist");
        if (::access(folder.empty() ? "." : folder.c_str(), W_OK) != 0)
            return fail(std::string(name) + ": folder " + (folder.empty() ? std::string(".") : folder.string()) + " is not writable");
        if (auto ok = check_new_file(name, file, o.overwrite); !ok) return std::unexpected(ok.error());
        for (std::size_t k = 0; k < i; ++k)
            if (!files[k].second.empty() && fs::path(files[k].second).lexically_normal() == fs::path(file).lexically_normal())
                return fail(std::string(name) + ": " + file + " is also the " + files[k].first + " file");
    }
    return s;
}

// ---------------------------------------------------------------------------------------
// 2. The scene: the file named, or the sample scene.
Result<SceneDescription> load_scene(const PlayOptions& o) {
    if (!o.scene.empty()) return load_scene_file(o.scene);
    SceneDescription scene = sample_scene();
    std::error_code ec;
    if (o.character.empty() && !fs::exists(scene.characters.at(0).file, ec))
        return fail("the sample scene's avatar is missing: " + scene.characters[0].file.string() +
                    " (run from the project folder, or set DRAPE_ASSETS to its assets/ folder)");
    return scene;
}

// ---------------------------------------------------------------------------------------
// 3. Command-line overrides of the scene, then the scene checked as a whole.
// Applies the command-line overrides to a scene.
Result<void> apply_overrides(SceneDescription& scene, const PlayOptions& o) {
    if (!o.character.empty()) {
        const fs::path file = o.character;
        std::error_code ec;
        if (!fs::exists(file, ec)) return fail("--character: no such file: " + file.string());
        if (!fs::is_regular_file(file, ec)) return fail("--character: not a regular file: " + file.string());
        use_character_file(scene, file);
    }
    if (!o.clip.empty()) scene.characters.at(0).clip = o.clip;
    if (!o.motion.empty()) {
        const fs::path file = o.motion;
        std::error_code ec;
        if (!fs::is_regular_file(file, ec)) return fail("--motion: no such file: " + file.string());
        if (!o.clip.empty()) return fail("--motion: give either --clip or --motion, not both");
        scene.characters.at(0).motion = file;
        scene.characters.at(0).clip.clear();
    }
    if (!o.garment.empty()) {
        if (o.garment == "none") {
            scene.garments.clear();
        } else {
            GarmentDescription g;
            const bool built_in = o.garment == "skirt" || o.garment == "dress";
            if (built_in) {
                g.type = o.garment == "dress" ? GarmentType::dress : GarmentType::skirt;
            } else {  // a garment file, FILE[:MESH]
                auto [file, mesh] = split_garment_reference(o.garment);
                std::error_code ec;
                if (!fs::is_regular_file(file, ec))
                    return fail("--garment: must be skirt, dress, none or a garment file (FILE[:MESH]); no such file: " + file.string());
                g.file = std::move(file);
                g.mesh = std::move(mesh);
            }
            if (!scene.garments.empty()) {  // keep the look and solver choices of the scene's garment
                g.model = scene.garments[0].model;
                g.integrator = scene.garments[0].integrator;
                g.warp_solve = scene.garments[0].warp_solve;
                g.pin_weights = scene.garments[0].pin_weights;
                g.collision = scene.garments[0].collision;
                g.color = scene.garments[0].color;
                if (built_in && scene.garments[0].file.empty() && scene.garments[0].type == g.type) g.parameters = scene.garments[0].parameters;
            }
            scene.garments = {g};
        }
    }
    if (!o.model.empty())
        for (GarmentDescription& g : scene.garments)
            g.model = o.model == "classic" ? ClothModel::classic : ClothModel::simplified;
    if (!o.integrator.empty())
        for (GarmentDescription& g : scene.garments)
            g.integrator = o.integrator == "paper" ? ClothIntegrator::paper : ClothIntegrator::shipped;
    if (!o.warp_solve.empty())
        for (GarmentDescription& g : scene.garments) g.warp_solve = o.warp_solve == "lines" ? WarpSolve::lines : WarpSolve::rounds;
    if (!o.pin_weights.empty())
        for (GarmentDescription& g : scene.garments)
            g.pin_weights = o.pin_weights == "skin_surface" ? PinWeights::skin_surface : PinWeights::nearest_vertex;
    if (o.threads) scene.solver.threads = *o.threads;
    if (o.time_scale) scene.solver.time_scale = *o.time_scale;
    return {};
}

Result<void> apply_command_line(SceneDescription& scene, const PlayOptions& o) {
    if (auto ok = apply_overrides(scene, o); !ok) return ok;
    return validate(scene);
}

// ---------------------------------------------------------------------------------------
// 4. The world (nothing has been written yet).
Result<World> build_play_world(const SceneDescription& scene, const PlayOptions& o, const PlaySettings& s) {
    WorldOptions options;
    options.render = !s.headless;
    options.window = s.window;
    options.width = s.size.first;
    options.height = s.size.second;
    options.skin_penetration = !o.stats.empty();  // the stats file reports cloth behind the skin
    auto built = build_world(scene, options);
    if (!built) {
        // A value from the command line is named as the option the user typed.
        std::string message = built.error().message;
        for (const auto& [field, option, given] : {std::tuple{"characters[0].clip: ", "--clip: ", !o.clip.empty()},
                                                   std::tuple{"characters[0].file: ", "--character: ", !o.character.empty()},
                                                   std::tuple{"characters[0].motion: ", "--motion: ", !o.motion.empty()}})
            if (given && message.rfind(field, 0) == 0) message = option + message.substr(std::string_view(field).size());
        return fail(message);
    }
    for (const std::string& warning : built->warnings) std::fprintf(stderr, "drape play: warning: %s\n", warning.c_str());
    return built;
}

// ---------------------------------------------------------------------------------------
// 5. Outputs: where frames go, created only now that the input is known good. Off-screen
//    with no output named: a new video (or frame folder) under out/, never over an old one.

/// The frame outputs of a run.
struct PlayOutputs {
    CreatedOutputs created;           ///< First member: outlives the video writer, whose file it may remove.
    fs::path video_file;              ///< The video as the user will find it (or empty).
    fs::path frame_folder;            ///< PNG frames (or empty).
    std::string partial_video;        ///< The video while it is written.
    bool video_named = false;         ///< --video was given: its errors say so.
    std::optional<VideoWriter> video;

    /// A video error naming the file the user knows, not the partial one being written.
    [[nodiscard]] Error video_error(std::string message) const {
        if (const auto at = message.find(partial_video); !partial_video.empty() && at != std::string::npos)
            message.replace(at, partial_video.size(), video_file.string());
        return Error{(video_named ? "--video: " : "") + message};
    }
};

Result<void> open_outputs(PlayOutputs& out, const PlayOptions& o, const PlaySettings& s) {
    out.video_file = o.video;
    out.frame_folder = o.out;
    out.video_named = !o.video.empty();
    if (!s.headless && !s.window && o.video.empty() && o.out.empty()) {
        const std::string stem = o.scene.empty() ? (o.character.empty() ? "sample" : fs::path(o.character).stem().string())
                                                 : fs::path(o.scene).stem().string();
        if (auto ok = out.created.create_folder("out"); !ok) return fail("out/: " + ok.error().message);
        if (find_ffmpeg())
            out.video_file = fresh_path("out", stem, ".mp4");
        else
            out.frame_folder = fresh_path("out", stem + "_frames", "");
    }
    if (!out.frame_folder.empty())
        if (auto ok = out.created.create_folder(out.frame_folder); !ok) return fail("--out: " + ok.error().message);
    out.partial_video = out.video_file.empty() ? std::string() : partial_path(out.video_file).string();
    if (!out.video_file.empty()) {
        auto opened = VideoWriter::open(out.partial_video, s.size.first, s.size.second, o.fps);
        if (!opened) return std::unexpected(out.video_error(opened.error().message));
        out.video.emplace(std::move(*opened));
    }
    return {};
}

// ---------------------------------------------------------------------------------------
// 6. The frames.

/// What the loop did.
struct PlayRun {
    int played = 0;                   ///< Frames played.
    std::uint64_t dropped_frames = 0; ///< Frames that dropped simulated time (hitches).
    bool interrupted = false;         ///< Stopped by Ctrl-C.
    std::vector<double> wall_ms;      ///< Each frame's whole wall-clock time: its step, drawing, presenting, writing.
};

#ifdef DRAPE_HAVE_RENDER
/// The window's keys and the frame time they give: the wall-clock time since the last
/// frame, none while paused, one fixed step for N.
struct WindowControl {
    InputState input;
    bool paused = false;
    bool hud = true;  ///< The overlay is shown (H).
    std::chrono::steady_clock::time_point last = std::chrono::steady_clock::now();

    /// False when the window was closed or Q pressed.
    bool next_frame(World& world, double& dt) {
        if (!world.renderer->poll_events(input) || input.has(Action::quit)) return false;
        bool step_once = false;
        for (Action a : input.actions) {
            switch (a) {
                case Action::toggle_pause: paused = !paused; break;
                case Action::step: step_once = true; break;
                case Action::toggle_ellipsoids: world.renderer->set_show_ellipsoids(!world.renderer->show_ellipsoids()); break;
                case Action::switch_model: {
                    const bool simplified = !world.scene.garments.empty() && world.scene.garments[0].model == ClothModel::simplified;
                    set_garment_model(world, simplified ? ClothModel::classic : ClothModel::simplified);
                    break;
                }
                case Action::reset: reset_garments(world); break;
                case Action::toggle_hud: hud = !hud; break;
                case Action::quit: break;
            }
        }
        const auto now = std::chrono::steady_clock::now();
        dt = std::chrono::duration<double>(now - last).count();
        last = now;
        if (paused) dt = step_once ? world.scheduler.settings().fixed_dt_s / std::max(1e-9, world.scheduler.settings().time_scale) : 0.0;
        return true;
    }
};

/// Shows the frame in the window and writes it to the video and the frame folder.
Result<void> show_and_record(World& world, PlayOutputs& out, bool window, int frame, Image& image) {
    if (!world.renderer) return {};
    if (window) {
        if (auto ok = world.renderer->present(); !ok) return ok;
    }
    if (out.video || !out.frame_folder.empty()) {
        if (auto ok = world.renderer->read_pixels(image); !ok) return ok;
        if (out.video)
            if (auto ok = out.video->write(image); !ok) return std::unexpected(out.video_error(ok.error().message));
        if (!out.frame_folder.empty()) {
            const fs::path file = out.frame_folder / frame_file_name(frame);
            out.created.add_file(file);
            if (auto ok = write_png(image, file); !ok) return ok;
        }
    }
    return {};
}
#endif

/// Ctrl-C ends the loop between frames while this lives.
class InterruptScope {
public:
    InterruptScope() : m_previous((g_interrupted = 0, std::signal(SIGINT, on_interrupt))) {}
    InterruptScope(const InterruptScope&) = delete;
    InterruptScope& operator=(const InterruptScope&) = delete;
    ~InterruptScope() { std::signal(SIGINT, m_previous); }

private:
    void (*m_previous)(int);
};

// With the overlay, a frame shows its own systems' times and the previous frame's whole
// wall time (this one's is not over until it has been shown and recorded).
Result<PlayRun> run_frames(World& world, const PlayOptions& o, const PlaySettings& s, PlayOutputs& out) {
    const int frames = o.frames.value_or(s.window ? 0 : 240);  // window: until closed unless --frames
    const double frame_dt_s = 1.0 / o.fps;
    PlayRun run;
#ifdef DRAPE_HAVE_RENDER
    WindowControl control;
    Image image;
    FrameHud hud;
    double wall_ms = 0;  // the previous frame's, from its start to the next one's
    auto title_shown = std::chrono::steady_clock::now();
#endif
    const InterruptScope interrupts;
    while ((frames == 0 || run.played < frames) && !g_interrupted) {
        double dt = frame_dt_s;
        const auto start = std::chrono::steady_clock::now();
#ifdef DRAPE_HAVE_RENDER
        if (s.window && !control.next_frame(world, dt)) break;
#endif
        auto ticked = step_world(world, dt);
        if (!ticked) return std::unexpected(ticked.error());
        if (ticked->dropped_s > 0) ++run.dropped_frames;
        ++run.played;
#ifdef DRAPE_HAVE_RENDER
        if (world.renderer && s.hud) {
            hud.record(world, wall_ms);
            if (!s.window || control.hud) world.renderer->draw_hud(hud.overlay());
            if (s.window && start - title_shown >= std::chrono::milliseconds(250)) {
                world.renderer->set_window_title(hud.title());
                title_shown = start;
            }
        }
        if (auto ok = show_and_record(world, out, s.window, run.played - 1, image); !ok) return std::unexpected(ok.error());
        wall_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
#else
        (void)out;
#endif
        run.wall_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
    run.interrupted = g_interrupted != 0;
    return run;
}

// ---------------------------------------------------------------------------------------
// 7. Closing the outputs: the video gets its name, the frame folder holds this run's
//    frames only (older frames past the last one go), and what the run made is kept.
Result<void> close_outputs(PlayOutputs& out, int played) {
    if (out.video) {
        if (auto ok = out.video->close(); !ok) return std::unexpected(out.video_error(ok.error().message));
        if (auto ok = commit_partial(out.video->file(), out.video_file); !ok) return ok;
    }
    if (!out.frame_folder.empty()) remove_frames_from(out.frame_folder, played);
    out.created.keep();
    return {};
}

// ---------------------------------------------------------------------------------------
// 8. The frame budget and where the frames went.
void print_budget(const World& world, const PlayRun& run, const PlayOutputs& out, const PlaySettings& s) {
    std::fputs(world.scheduler.profiler().table().c_str(), stdout);
    if (!run.wall_ms.empty()) {
        // The systems above are the simulation's and the drawing's share; a frame's wall time
        // also holds presenting, reading back and writing the frames or the video.
        std::vector<double> w = run.wall_ms;
        std::sort(w.begin(), w.end());
        const auto at = [&](double q) { return w[std::min(w.size() - 1, static_cast<std::size_t>(q * double(w.size())))]; };
        double sum = 0;
        for (const double v : w) sum += v;
        std::printf("%-28s %8zu %8s %9.4f %9.4f %9.4f %9.4f\n", "whole frame (wall clock)", w.size(), "", sum / double(w.size()),
                    at(0.5), at(0.95), w.back());
    }
    std::printf("%d frames, %.2f s simulated", run.played, world.scheduler.time_s());
    if (world.scheduler.total_dropped_s() > 0)
        std::printf(", %.3f s dropped in %llu hitch frame(s)", world.scheduler.total_dropped_s(),
                    static_cast<unsigned long long>(run.dropped_frames));
    if (world.teleports->teleports > 0)
        std::printf(", %llu teleport(s)", static_cast<unsigned long long>(world.teleports->teleports));
    std::printf("\n");
    if (out.video) std::printf("video: %s\n", out.video_file.c_str());
    if (!out.frame_folder.empty() && !s.headless) std::printf("frames: %s/frame_%%05d.png\n", out.frame_folder.c_str());
}

// ---------------------------------------------------------------------------------------
// 9. The verdict: one line per garment on the quality contract (game/contract.hpp), on
//    stdout when it was kept, as a warning on stderr when not. Returns the garments that
//    broke it.
int print_verdict(const World& world) {
    if (world.watch.frames() == 0) return 0;  // nothing was measured
    const RunStats stats = run_stats(world);
    const std::vector<std::string> names = garment_names(world.scene);
    int broken = 0;
    for (std::size_t i = 0; i < stats.garments.size(); ++i) {
        const std::string name = i < names.size() ? names[i] : "garments[" + std::to_string(i) + "]";
        const std::string line = garment_verdict(name, stats.garments[i]);
        if (contract_breaches(stats.garments[i]).empty()) {
            std::printf("%s\n", line.c_str());
        } else {
            ++broken;
            std::fflush(stdout);
            std::fprintf(stderr, "drape play: warning: %s\n", line.c_str());
        }
    }
    return broken;
}

// ---------------------------------------------------------------------------------------
// 10. Reports: the trace and the stats, each through a partial file; then the run's own
//    verdict. Each failure is reported; the exit status is 1 when any failed.

/// Writes one report through a partial file; the error is prefixed with `option`.
template <class Write>
Result<void> write_report(const char* option, const fs::path& file, Write write) {
    const fs::path partial = partial_path(file);
    auto ok = write(partial);
    if (ok) ok = commit_partial(partial, file);
    if (!ok) {
        std::error_code ec;
        fs::remove(partial, ec);
        return fail(std::string(option) + ": " + ok.error().message);
    }
    return {};
}

int write_reports(const World& world, const PlayOptions& o) {
    int status = 0;
    if (!o.trace.empty()) {
        const FrameProfiler& profiler = world.scheduler.profiler();
        if (auto ok = write_report("--trace", o.trace, [&](const fs::path& p) { return profiler.write_trace(p); }); !ok) {
            status = report(ok.error().message);
        } else {
            const auto recorded = static_cast<unsigned long long>(profiler.trace_events_recorded());
            const auto dropped = static_cast<unsigned long long>(profiler.trace_events_dropped());
            std::printf("trace: %s, %llu events\n", o.trace.c_str(), recorded - dropped);
            if (dropped > 0) {
                std::fflush(stdout);
                std::fprintf(stderr,
                             "drape play: warning: --trace: %llu of %llu events were dropped: the trace keeps the last %zu "
                             "(--trace-size N keeps more)\n",
                             dropped, recorded, profiler.trace_capacity());
            }
        }
    }
    if (!o.stats.empty())
        if (auto ok = write_report("--stats", o.stats, [&](const fs::path& p) { return write_stats(run_stats(world), p); }); !ok)
            status = report(ok.error().message);
    if (has_nonfinite(world)) status = report("the simulation produced non-finite values (see --stats FILE for which garment)");
    return status;
}

// ---------------------------------------------------------------------------------------
int play(const PlayOptions& o) {
    const auto settings = check_options(o);
    if (!settings) return report(settings.error().message);
    auto scene = load_scene(o);
    if (!scene) return report(scene.error().message);
    if (auto ok = apply_command_line(*scene, o); !ok) return report(ok.error().message);
    auto world = build_play_world(*scene, o, *settings);
    if (!world) return report(world.error().message);
    if (o.trace_size) world->scheduler.profiler().set_trace_capacity(static_cast<std::size_t>(*o.trace_size));
    PlayOutputs outputs;
    if (auto ok = open_outputs(outputs, o, *settings); !ok) return report(ok.error().message);

    const std::string what = !o.scene.empty() ? o.scene : !o.character.empty() ? o.character : "sample scene";
    std::printf("drape play: %s, %zu character(s), %zu garment(s), %s\n", what.c_str(), world->characters.size(),
                world->garments.size(), settings->headless ? "headless" : settings->window ? "window" : "off-screen");
    const auto run = run_frames(*world, o, *settings, outputs);
    if (!run) return report(run.error().message);
    if (auto ok = close_outputs(outputs, run->played); !ok) return report(ok.error().message);
    if (run->interrupted) std::printf("drape play: interrupted after %d frames\n", run->played);

    print_budget(*world, *run, outputs, *settings);
    const int broken = print_verdict(*world);
    const int status = write_reports(*world, o);
    if (broken > 0 && o.strict)
        return report(std::to_string(broken) + " garment(s) outside the contract (--strict)");
    return status;
}

}  // namespace

void add_play_command(CLI::App& app) {
    auto o = std::make_shared<PlayOptions>();
    CLI::App* play_app = app.add_subcommand("play", "Play a scene (default: the sample scene) and print the frame budget");
    play_app->add_option("--scene", o->scene, "Scene file (JSON, see docs/scenes.md); default: the sample scene")->check(not_empty());
    play_app->add_option("--character", o->character, "Character file (.glb/.gltf/.fbx/...) replacing the scene's first character")->check(not_empty());
    play_app->add_option("--clip", o->clip, "Clip of the first character: name or index")->check(not_empty());
    play_app->add_option("--motion", o->motion,
                         "BVH file whose motion drives the first character, retargeted by bone names (docs/characters.md)")
        ->check(not_empty());
    play_app->add_option("--garment", o->garment,
                         "Dress the first character in a default skirt or dress, a garment file (FILE[:MESH], docs/garments.md), or nothing")
        ->check(not_empty());
    play_app->add_option("--model", o->model, "Garment model: the paper's simplified mass-spring or the classic baseline")
        ->check(one_of({"simplified", "classic"}));
    play_app->add_option("--integrator", o->integrator,
                         "Garment integrator: the shipped solver or the paper's explicit scheme (docs/cloth.md)")
        ->check(one_of({"shipped", "paper"}));
    play_app->add_option("--warp-solve", o->warp_solve,
                         "The shipped solver's warp springs: Gauss-Seidel rounds or each line at once (docs/cloth.md)")
        ->check(one_of({"rounds", "lines"}));
    play_app->add_option("--pin-weights", o->pin_weights,
                         "Skinned pins take the nearest skin vertex's weights or the skin's where they sit (docs/cloth.md)")
        ->check(one_of({"nearest_vertex", "skin_surface"}));
    play_app->add_option("--frames", o->frames, "Frames to play (default 240; in a window: until closed)")
        ->check(integer_in(1, 10'000'000));
    play_app->add_flag("--headless", o->headless, "No rendering at all (no render system)");
    play_app->add_option("--out", o->out, "Write every frame as PNG into this folder")->check(not_empty());
    play_app->add_option("--video", o->video, "Write an H.264 video (frames piped to ffmpeg)")->check(not_empty());
    play_app->add_flag("--window", o->window, "Show the scene in an X11 window (mouse: orbit; keys: space, N, E, M, R, H, Q)");
    play_app->add_flag("--hud", o->hud,
                       "Draw the frame budget overlay into the frames and video (in a window it is on; H toggles it)");
    play_app->add_option("--size", o->size, "Frame size WIDTHxHEIGHT (default 1280x720)")->check(not_empty());
    play_app->add_option("--fps", o->fps, "Frames per second of off-screen playback and video (default 60)")
        ->check(number_in(1, 1000));
    play_app->add_option("--trace", o->trace, "Write Chrome trace event JSON (Perfetto, chrome://tracing)")->check(not_empty());
    play_app->add_option("--trace-size", o->trace_size, "Trace events kept, the most recent (default 16384)")
        ->check(integer_in(16, 10'000'000));
    play_app->add_option("--stats", o->stats, "Write run statistics JSON (systems, garments)")->check(not_empty());
    play_app->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(integer_in(0, 1024));
    play_app->add_option("--time-scale", o->time_scale, "Simulated seconds per wall-clock second (slow motion < 1)")
        ->check(number_in(0, 1000));
    play_app->add_flag("--strict", o->strict, "Exit with status 1 when a garment breaks the quality contract (the verdict)");
    play_app->add_flag("--overwrite", o->overwrite,
                       "Replace the --stats, --trace, --video files and --out frames if they exist (else: an error)");
    play_app->callback([o] { command_exit_code() = play(*o); });
}

}  // namespace drape
