// `drape play`: builds a scene (the sample scene by default), runs it for a number of
// frames, writes what was asked (PNG frames, a video, a trace, stats) and prints the frame
// budget. Usage and options: README.md "Playing scenes" and `drape play --help`.

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

#include "game/commands.hpp"
#include "game/output_files.hpp"
#include "game/sample_scene.hpp"
#include "game/scene_file.hpp"
#include "game/world.hpp"
#include "game/stats.hpp"
#include "game/video.hpp"

#ifdef DRAPE_HAVE_RENDER
#include "engine/render/renderer.hpp"
#endif

namespace drape {

namespace {

namespace fs = std::filesystem;

struct PlayOptions {
    std::string scene, character, clip, garment, model, out, video, trace, stats, size;
    std::optional<int> frames;
    std::optional<int> threads;
    std::optional<double> time_scale;
    double fps = 60;
    bool headless = false, window = false, overwrite = false;
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

// Applies the command-line overrides to a scene.
Result<void> apply_overrides(SceneDescription& scene, const PlayOptions& o) {
    if (!o.character.empty()) {
        const fs::path file = o.character;
        std::error_code ec;
        if (!fs::exists(file, ec)) return fail("--character: no such file: " + file.string());
        if (!fs::is_regular_file(file, ec)) return fail("--character: not a regular file: " + file.string());
        if (scene.characters.empty()) scene.characters.emplace_back();
        scene.characters[0].file = file;
        scene.characters[0].clip.clear();  // the sample's clip name means nothing to another file
        scene.characters[0].where = {};
        // Overrides name bones of the scene's own character.
        std::erase_if(scene.colliders, [](const ColliderOverride& c) { return c.character == 0; });
    }
    if (!o.clip.empty()) scene.characters.at(0).clip = o.clip;
    if (!o.garment.empty()) {
        if (o.garment == "none") {
            scene.garments.clear();
        } else {
            GarmentDescription g;
            g.type = o.garment == "dress" ? GarmentType::dress : GarmentType::skirt;
            if (!scene.garments.empty()) {  // keep the look and solver choices of the scene's garment
                g.model = scene.garments[0].model;
                g.collision = scene.garments[0].collision;
                g.color = scene.garments[0].color;
                if (scene.garments[0].type == g.type) g.parameters = scene.garments[0].parameters;
            }
            scene.garments = {g};
        }
    }
    if (!o.model.empty())
        for (GarmentDescription& g : scene.garments)
            g.model = o.model == "classic" ? ClothModel::classic : ClothModel::simplified;
    if (o.threads) scene.solver.threads = *o.threads;
    if (o.time_scale) scene.solver.time_scale = *o.time_scale;
    return {};
}

int play(const PlayOptions& o) {
    // --- Checks that need no scene; nothing is written before every input is checked.
    // (Option ranges, NaN included, are checked by the command line's validators.)
    std::pair<int, int> size{1280, 720};
    if (!o.size.empty()) {
        auto s = parse_size(o.size);
        if (!s) return report(s.error().message);
        size = *s;
    }
    if (o.headless) {
        if (o.window) return report("--headless: cannot be combined with --window (nothing is rendered)");
        if (!o.out.empty()) return report("--headless: cannot be combined with --out (nothing is rendered)");
        if (!o.video.empty()) return report("--headless: cannot be combined with --video (nothing is rendered)");
    }
    bool headless = o.headless;
    if (!render_available()) {
        if (o.window) return report("--window: this build has no render module (configured with -DDRAPE_RENDER=OFF)");
        if (!o.out.empty()) return report("--out: this build has no render module (configured with -DDRAPE_RENDER=OFF)");
        if (!o.video.empty()) return report("--video: this build has no render module (configured with -DDRAPE_RENDER=OFF)");
        if (!headless) std::printf("drape play: the render module is not built (-DDRAPE_RENDER=OFF): playing headless\n");
        headless = true;
    }
    if (!o.video.empty() && !find_ffmpeg())
        return report("--video: ffmpeg is not installed (apt-get install ffmpeg); --out DIR writes PNG frames instead");
    if (!o.out.empty()) {
        std::error_code ec;
        if (fs::exists(o.out, ec) && !fs::is_directory(o.out, ec)) return report("--out: " + o.out + " exists and is not a folder");
        if (!o.overwrite && fs::is_directory(o.out, ec) && !frame_files(o.out).empty())
            return report("--out: " + o.out + " already holds frames (frame_00000.png, ...); add --overwrite to replace them");
    }
    if (!headless && !o.window && o.video.empty() && o.out.empty()) {  // the default output goes under out/
        std::error_code ec;
        if (fs::exists("out", ec) && !fs::is_directory("out", ec))
            return report("out: exists and is not a folder (the default output goes there; name one with --video or --out)");
    }
    const std::array<std::pair<const char*, std::string>, 3> files{
        {{"--stats", o.stats}, {"--trace", o.trace}, {"--video", o.video}}};
    for (std::size_t i = 0; i < files.size(); ++i) {
        const auto& [name, file] = files[i];
        if (file.empty()) continue;
        std::error_code ec;
        const fs::path folder = fs::path(file).parent_path();
        if (!folder.empty() && !fs::is_directory(folder, ec))
            return report(std::string(name) + ": folder " + folder.string() + " does not exist");
        if (::access(folder.empty() ? "." : folder.c_str(), W_OK) != 0)
            return report(std::string(name) + ": folder " + (folder.empty() ? std::string(".") : folder.string()) + " is not writable");
        if (auto ok = check_new_file(name, file, o.overwrite); !ok) return report(ok.error().message);
        for (std::size_t k = 0; k < i; ++k)
            if (!files[k].second.empty() && fs::path(files[k].second).lexically_normal() == fs::path(file).lexically_normal())
                return report(std::string(name) + ": " + file + " is also the " + files[k].first + " file");
    }

    // --- The scene.
    SceneDescription scene;
    if (!o.scene.empty()) {
        auto loaded = load_scene_file(o.scene);
        if (!loaded) return report(loaded.error().message);
        scene = std::move(*loaded);
    } else {
        scene = sample_scene();
        std::error_code ec;
        if (o.character.empty() && !fs::exists(scene.characters.at(0).file, ec))
            return report("the sample scene's avatar is missing: " + scene.characters[0].file.string() +
                          " (run from the project folder, or set DRAPE_ASSETS to its assets/ folder)");
    }
    if (auto ok = apply_overrides(scene, o); !ok) return report(ok.error().message);
    if (auto ok = validate(scene); !ok) return report(ok.error().message);

    // --- The world (nothing has been written yet).
    const bool window = o.window && !headless;
    WorldOptions options;
    options.render = !headless;
    options.window = window;
    options.width = size.first;
    options.height = size.second;
    auto built = build_world(scene, options);
    if (!built) {
        // A value from the command line is named as the option the user typed.
        std::string message = built.error().message;
        for (const auto& [field, option, given] : {std::tuple{"characters[0].clip: ", "--clip: ", !o.clip.empty()},
                                                   std::tuple{"characters[0].file: ", "--character: ", !o.character.empty()}})
            if (given && message.rfind(field, 0) == 0) message = option + message.substr(std::string_view(field).size());
        return report(message);
    }
    World& world = *built;
    for (const std::string& warning : world.warnings) std::fprintf(stderr, "drape play: warning: %s\n", warning.c_str());

    // --- Where frames go, created only now that the input is known good. Off-screen with
    // no output named: a new video (or frame folder) under out/, never over an old one.
    CreatedOutputs created;
    fs::path video_file = o.video, frame_folder = o.out;
    if (!headless && !window && o.video.empty() && o.out.empty()) {
        const std::string stem = o.scene.empty() ? (o.character.empty() ? "sample" : fs::path(o.character).stem().string())
                                                 : fs::path(o.scene).stem().string();
        if (auto ok = created.create_folder("out"); !ok) return report("out/: " + ok.error().message);
        if (find_ffmpeg())
            video_file = fresh_path("out", stem, ".mp4");
        else
            frame_folder = fresh_path("out", stem + "_frames", "");
    }
    if (!frame_folder.empty())
        if (auto ok = created.create_folder(frame_folder); !ok) return report("--out: " + ok.error().message);

    const int frames = o.frames.value_or(window ? 0 : 240);  // window: until closed unless --frames
    const double frame_dt_s = 1.0 / o.fps;
    std::optional<VideoWriter> video;
    // Video errors name the file the user knows, not the partial one being written.
    const std::string partial_video = video_file.empty() ? std::string() : partial_path(video_file).string();
    auto video_error = [&](std::string message) {
        if (const auto at = message.find(partial_video); !partial_video.empty() && at != std::string::npos)
            message.replace(at, partial_video.size(), video_file.string());
        return report((o.video.empty() ? "" : "--video: ") + message);
    };
    if (!video_file.empty()) {
        auto opened = VideoWriter::open(partial_video, size.first, size.second, o.fps);
        if (!opened) return video_error(opened.error().message);
        video.emplace(std::move(*opened));
    }

    const std::string what = !o.scene.empty() ? o.scene : !o.character.empty() ? o.character : "sample scene";
    std::printf("drape play: %s, %zu character(s), %zu garment(s), %s\n", what.c_str(), world.characters.size(), world.garments.size(),
                headless ? "headless" : window ? "window" : "off-screen");

    // --- The loop.
    std::uint64_t dropped_frames = 0;
    int played = 0;
#ifdef DRAPE_HAVE_RENDER
    InputState input;
    Image image;
    bool paused = false;
    auto last = std::chrono::steady_clock::now();
#endif
    g_interrupted = 0;
    const auto previous_handler = std::signal(SIGINT, on_interrupt);
    while ((frames == 0 || played < frames) && !g_interrupted) {
        double dt = frame_dt_s;
#ifdef DRAPE_HAVE_RENDER
        if (window) {
            if (!world.renderer->poll_events(input) || input.has(Action::quit)) break;
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
                    case Action::quit: break;
                }
            }
            const auto now = std::chrono::steady_clock::now();
            dt = std::chrono::duration<double>(now - last).count();
            last = now;
            if (paused) dt = step_once ? world.scheduler.settings().fixed_dt_s / std::max(1e-9, world.scheduler.settings().time_scale) : 0.0;
        }
#endif
        auto ticked = step_world(world, dt);
        if (!ticked) return report(ticked.error().message);
        if (ticked->dropped_s > 0) ++dropped_frames;
        ++played;
#ifdef DRAPE_HAVE_RENDER
        if (world.renderer) {
            if (window) {
                if (auto ok = world.renderer->present(); !ok) return report(ok.error().message);
            }
            if (video || !frame_folder.empty()) {
                if (auto ok = world.renderer->read_pixels(image); !ok) return report(ok.error().message);
                if (video)
                    if (auto ok = video->write(image); !ok) return video_error(ok.error().message);
                if (!frame_folder.empty()) {
                    const fs::path file = frame_folder / frame_file_name(played - 1);
                    created.add_file(file);
                    if (auto ok = write_png(image, file); !ok) return report(ok.error().message);
                }
            }
        }
#endif
    }
    std::signal(SIGINT, previous_handler);
    if (video) {
        if (auto ok = video->close(); !ok) return video_error(ok.error().message);
        if (auto ok = commit_partial(video->file(), video_file); !ok) return report(ok.error().message);
    }
    // The folder now holds this run's frames only (older frames past the last one go).
    if (!frame_folder.empty()) remove_frames_from(frame_folder, played);
    created.keep();
    if (g_interrupted) std::printf("drape play: interrupted after %d frames\n", played);

    // --- Reports.
    std::fputs(world.scheduler.profiler().table().c_str(), stdout);
    std::printf("%d frames, %.2f s simulated", played, world.scheduler.time_s());
    if (world.scheduler.total_dropped_s() > 0)
        std::printf(", %.3f s dropped in %llu hitch frame(s)", world.scheduler.total_dropped_s(),
                    static_cast<unsigned long long>(dropped_frames));
    if (world.teleports->teleports > 0)
        std::printf(", %llu teleport(s)", static_cast<unsigned long long>(world.teleports->teleports));
    std::printf("\n");
    if (video) std::printf("video: %s\n", video_file.c_str());
    if (!frame_folder.empty() && !headless) std::printf("frames: %s/frame_%%05d.png\n", frame_folder.c_str());
    int status = 0;
    if (!o.trace.empty()) {
        const fs::path partial = partial_path(o.trace);
        auto ok = world.scheduler.profiler().write_trace(partial);
        if (ok) ok = commit_partial(partial, o.trace);
        if (!ok) {
            std::error_code ec;
            fs::remove(partial, ec);
            status = report("--trace: " + ok.error().message);
        }
    }
    if (!o.stats.empty()) {
        const fs::path partial = partial_path(o.stats);
        auto ok = write_stats(run_stats(world), partial);
        if (ok) ok = commit_partial(partial, o.stats);
        if (!ok) {
            std::error_code ec;
            fs::remove(partial, ec);
            status = report("--stats: " + ok.error().message);
        }
    }
    if (has_nonfinite(world)) status = report("the simulation produced non-finite values (see --stats FILE for which garment)");
    return status;
}

}  // namespace

void add_play_command(CLI::App& app) {
    auto o = std::make_shared<PlayOptions>();
    CLI::App* play_app = app.add_subcommand("play", "Play a scene (default: the sample scene) and print the frame budget");
    play_app->add_option("--scene", o->scene, "Scene file (JSON, see docs/scenes.md); default: the sample scene")->check(not_empty());
    play_app->add_option("--character", o->character, "Character file (.glb/.gltf/.fbx/...) replacing the scene's first character")->check(not_empty());
    play_app->add_option("--clip", o->clip, "Clip of the first character: name or index")->check(not_empty());
    play_app->add_option("--garment", o->garment, "Dress the first character in a default skirt or dress, or nothing")
        ->check(one_of({"skirt", "dress", "none"}));
    play_app->add_option("--model", o->model, "Garment model: the paper's simplified mass-spring or the classic baseline")
        ->check(one_of({"simplified", "classic"}));
    play_app->add_option("--frames", o->frames, "Frames to play (default 240; in a window: until closed)")
        ->check(integer_in(1, 10'000'000));
    play_app->add_flag("--headless", o->headless, "No rendering at all (no render system)");
    play_app->add_option("--out", o->out, "Write every frame as PNG into this folder")->check(not_empty());
    play_app->add_option("--video", o->video, "Write an H.264 video (frames piped to ffmpeg)")->check(not_empty());
    play_app->add_flag("--window", o->window, "Show the scene in an X11 window (mouse: orbit; keys: space, N, E, M, R, Q)");
    play_app->add_option("--size", o->size, "Frame size WIDTHxHEIGHT (default 1280x720)")->check(not_empty());
    play_app->add_option("--fps", o->fps, "Frames per second of off-screen playback and video (default 60)")
        ->check(number_in(1, 1000));
    play_app->add_option("--trace", o->trace, "Write Chrome trace event JSON (Perfetto, chrome://tracing)")->check(not_empty());
    play_app->add_option("--stats", o->stats, "Write run statistics JSON (systems, garments)")->check(not_empty());
    play_app->add_option("--threads", o->threads, "Worker threads (0 = all cores)")->check(integer_in(0, 1024));
    play_app->add_option("--time-scale", o->time_scale, "Simulated seconds per wall-clock second (slow motion < 1)")
        ->check(number_in(0, 1000));
    play_app->add_flag("--overwrite", o->overwrite,
                       "Replace the --stats, --trace, --video files and --out frames if they exist (else: an error)");
    play_app->callback([o] { command_exit_code() = play(*o); });
}

}  // namespace drape
