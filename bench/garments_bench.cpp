// `drape bench garments`: garments from files (docs/garments.md) on every character, walking
// and running, judged by the contract after every whole frame, with their cost.
//
// For each character (the default avatar and each shared character file) and each of its
// walk and run clips, the four garments of game/garment_patterns.hpp are cut for the
// character as it stands in the clip's first pose, written as glTF, read back and played
// for 240 frames in place, one thread unless --threads; the built-in skirt is played on the
// same character and clip in the same run, so that the cost per particle of a resampled
// grid (the four-panel flared skirt) is compared with the built-in grid's side by side.
// Nothing is tuned per case. `--filter WORDS` keeps the cases whose name ("character clip
// garment") holds every comma-separated word.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "bench/characters.hpp"
#include "bench/contact_sheet.hpp"
#include "bench/probe.hpp"
#include "bench/report.hpp"
#include "bench/world.hpp"
#include "drape/components/animation_player.hpp"
#include "drape/components/garment.hpp"
#include "drape/engine/assets/character_import.hpp"
#include "drape/engine/assets/garment_file.hpp"
#include "drape/engine/render/image.hpp"
#include "drape/game/contract.hpp"
#include "drape/game/garment_patterns.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/stats.hpp"

#ifdef DRAPE_HAVE_RENDER
#include "drape/engine/render/renderer.hpp"
#endif

namespace drape::bench {

namespace {

namespace fs = std::filesystem;

constexpr double frame_dt_s = 1.0 / 60.0;
constexpr int run_frames = 240;
constexpr int sheet_frames = 4;
constexpr int tile_width = 200, tile_height = 250, render_scale = 2;

struct GarmentRun {
    std::string character, clip, kind, garment;  // garment: a cut garment's name, or "built-in skirt"
    std::string error;
    GarmentStats stats;
    std::size_t particles = 0;
    double ms_p50 = 0, ms_p95 = 0;
    [[nodiscard]] std::string name() const { return character + " " + clip + " " + garment; }
    [[nodiscard]] std::string broken() const {
        if (!error.empty()) return error;
        std::string why;
        for (const std::string& breach : contract_breaches(stats)) why += (why.empty() ? "" : ", ") + breach;
        return why;
    }
    [[nodiscard]] bool within() const { return broken().empty(); }
};

// The character playing `clip` in place from its start, dressed in `garment`.
SceneDescription dressed(const CharacterFile& character, const std::string& clip, const GarmentDescription& garment, int threads) {
    SceneDescription scene = sample_scene();
    CharacterDescription& c = scene.characters.at(0);
    if (!character.default_avatar) {
        c = CharacterDescription{};
        c.file = character.file;
    }
    c.clip = clip;
    c.in_place = true;
    scene.garments = {garment};
    scene.solver.threads = threads;
    return scene;
}

// Plays `run`'s scene for run_frames; fills its figures, and grabs `grab` frames when rendering.
void play(GarmentRun& run, const SceneDescription& scene, bool render, const std::vector<int>& grab, std::vector<Image>* frames) {
    WorldOptions options;
#ifdef DRAPE_HAVE_RENDER
    options.render = render;
    options.width = tile_width * render_scale;
    options.height = tile_height * render_scale;
#else
    (void)render, (void)grab, (void)frames;
#endif
    auto world = build_world(scene, options);
    if (!world) {
        run.error = world.error().message;
        return;
    }
    run.particles = world->registry.get<Garment>(world->garments.at(0)).fabric->particle_count();
    std::vector<double> ms;
    for (int frame = 0; frame < run_frames; ++frame) {
        const double before = cloth_system_totals(world->scheduler).garment_ms;
        if (auto ok = step_world(*world, frame_dt_s); !ok) {
            run.error = ok.error().message;
            return;
        }
        ms.push_back(cloth_system_totals(world->scheduler).garment_ms - before);
#ifdef DRAPE_HAVE_RENDER
        if (frames && world->renderer && std::find(grab.begin(), grab.end(), frame) != grab.end()) {
            auto image = world->renderer->read_pixels();
            if (image) frames->push_back(std::move(*image));
        }
#endif
    }
    run.stats = run_stats(*world).garments.at(0);
    std::sort(ms.begin(), ms.end());
    run.ms_p50 = median(ms);
    run.ms_p95 = ms[static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(ms.size()))) - 1];
}

std::string pct(double x) { return fixed(100 * x, 1) + " %"; }
std::string mm(double m) { return fixed(1000 * m, 1) + " mm"; }

}  // namespace

Result<void> run_garments(const BenchOptions& options) {
    const fs::path scratch = fs::temp_directory_path() / ("drape_bench_garments_" + std::to_string(::getpid()));
    std::error_code ec;
    fs::create_directories(scratch, ec);
    if (ec) return fail(scratch.string() + ": " + ec.message());
    std::vector<GarmentRun> runs;
    std::vector<std::string> left_out;
    std::vector<std::pair<SceneDescription, std::string>> sheet;  // the default avatar's walk, one row per garment
    int cuts = 0;
    for (const CharacterFile& character : character_files()) {
        auto asset = import_character(character.file);
        if (!asset) {
            left_out.push_back(character.name + ": " + asset.error().message);
            continue;
        }
        for (const auto& [kind, clip] : chosen_clips(**asset)) {
            if (kind != "walk" && kind != "run") continue;
            bool wanted = options.filter.empty();
            for (const char* g : {"built-in skirt", "flared_skirt", "wrap_skirt", "panel_dress", "cape"})
                wanted = wanted || matches_filter(character.name + " " + clip->name + " " + g, options.filter);
            if (!wanted) continue;
            ++cuts;
            SceneDescription base = dressed(character, clip->name, GarmentDescription{}, options.threads);
            auto cut = cut_garments(base);
            if (!cut) {
                left_out.push_back(character.name + " " + clip->name + ": " + cut.error().message);
                continue;
            }
            std::vector<std::pair<GarmentDescription, std::string>> garments = {{GarmentDescription{}, "built-in skirt"}};
            for (const CutGarment& g : *cut) {
                const fs::path file = scratch / (std::to_string(cuts) + "_" + g.name + ".glb");
                if (auto ok = write_garment_mesh(file, g.mesh); !ok) return fail(ok.error().message);
                GarmentDescription d;
                d.file = file;
                d.color = g.color;
                garments.emplace_back(d, g.name);
            }
            for (const auto& [garment, name] : garments) {
                GarmentRun run;
                run.character = character.name;
                run.clip = clip->name;
                run.kind = kind;
                run.garment = name;
                if (!matches_filter(run.name(), options.filter)) continue;
                const SceneDescription scene = dressed(character, clip->name, garment, options.threads);
                play(run, scene, false, {}, nullptr);
                std::fprintf(stderr, "drape bench garments: %s: %s\n", run.name().c_str(), run.within() ? "within the contract" : run.broken().c_str());
                if (character.default_avatar && kind == "walk" && name != "built-in skirt") sheet.emplace_back(scene, name);
                runs.push_back(std::move(run));
            }
        }
    }
    if (runs.empty()) {
        fs::remove_all(scratch, ec);
        return fail("no case matched (--filter '" + options.filter + "')");
    }

    // Contact sheet: each garment on the default avatar's walk, four frames.
    std::string sheet_error;
#ifdef DRAPE_HAVE_RENDER
    if (!sheet.empty()) {
        Image image = blank_sheet(sheet_frames, static_cast<int>(sheet.size()), tile_width, tile_height);
        std::vector<int> grab;
        for (int k = 0; k < sheet_frames; ++k) grab.push_back((k + 1) * run_frames / sheet_frames - 1);
        for (std::size_t row = 0; row < sheet.size(); ++row) {
            GarmentRun again;
            std::vector<Image> frames;
            play(again, sheet[row].first, true, grab, &frames);
            for (std::size_t k = 0; k < frames.size(); ++k)
                put_tile(image, frames[k], static_cast<int>(k) * (tile_width + 4), static_cast<int>(row) * (tile_height + 4), render_scale);
        }
        fs::create_directories(options.out_dir, ec);
        if (auto ok = write_png(image, options.out_dir / "garments.png"); !ok) sheet_error = ok.error().message;
    }
#else
    sheet_error = "this build has no render module (configured with -DDRAPE_RENDER=OFF)";
#endif
    fs::remove_all(scratch, ec);

    // --- Report ---------------------------------------------------------------------------
    Report report("Garments from files", options, describe_machine());
    int within = 0, files = 0, files_within = 0;
    for (const GarmentRun& r : runs) {
        within += r.within();
        if (r.garment != "built-in skirt") files += 1, files_within += r.within();
    }
    // Cost per particle: the flared skirt's resampled grid against the built-in skirt's, same
    // character and clip, same run.
    std::vector<double> ratios;
    for (const GarmentRun& flared : runs) {
        if (flared.garment != "flared_skirt" || !flared.error.empty() || flared.particles == 0) continue;
        for (const GarmentRun& skirt : runs)
            if (skirt.garment == "built-in skirt" && skirt.character == flared.character && skirt.clip == flared.clip && skirt.error.empty() &&
                skirt.particles > 0 && skirt.ms_p50 > 0)
                ratios.push_back((flared.ms_p50 / double(flared.particles)) / (skirt.ms_p50 / double(skirt.particles)));
    }
    report.paragraph(
        "Each character's walk and run (the first clip of each kind), in place from the clip's start, " + std::to_string(run_frames) +
        " frames at 1/60 s, one run per case (times: the cloth systems' p50 and p95 per frame of that run), " +
        std::to_string(options.threads) + " thread(s); the four garments of `drape make-garments` cut for the character in the clip's first pose, written as glTF, read "
        "back and gridded from their patterns at the default spacing (0.029 m); the built-in skirt beside them. The contract after "
        "every whole frame (docs/cloth.md): strain p99 <= 10 %, max <= 20 %, no spring under 25 % of its rest length, rise above the "
        "pins <= 15 cm, penetration after the frame <= 2 mm, nothing non-finite. Nothing here was tuned per case; the garments' cut "
        "(lengths, flares, the cape's shoulder line) was chosen by looking at the default avatar only.");
    report.targets({
        Target{"garments from files within the contract", "all", std::to_string(files_within) + " of " + std::to_string(files),
               files_within == files, ""},
        Target{"cost per particle, resampled flared skirt / built-in skirt (median over characters and clips)", "<= 1.20",
               ratios.empty() ? "not measured" : fixed(median(ratios), 2), !ratios.empty() && median(ratios) <= 1.2, ""},
    });
    std::vector<std::vector<std::string>> rows;
    for (const GarmentRun& r : runs)
        rows.push_back({r.character, r.clip, r.garment, r.error.empty() ? std::to_string(r.particles) : "-",
                        r.error.empty() ? pct(r.stats.strain_p99) : "-", r.error.empty() ? pct(r.stats.strain_max) : "-",
                        r.error.empty() ? pct(r.stats.compression_min) : "-", r.error.empty() ? mm(r.stats.penetration_after_frame_m) : "-",
                        r.error.empty() ? fixed(100 * r.stats.rise_above_pins_m, 1) + " cm" : "-", r.error.empty() ? fixed(r.ms_p50, 3) : "-",
                        r.error.empty() ? fixed(r.ms_p95, 3) : "-", r.within() ? "within" : r.broken()});
    report.heading("Runs");
    report.paragraph(std::to_string(within) + " of " + std::to_string(runs.size()) + " runs within the contract (" +
                     std::to_string(files_within) + " of " + std::to_string(files) + " garments from files).");
    report.table({"character", "clip", "garment", "particles", "strain p99", "strain max", "shortest spring", "penetration",
                  "rise", "cloth ms p50", "p95", "verdict"},
                 rows);
    if (!left_out.empty()) {
        report.heading("Left out");
        std::string text;
        for (const std::string& l : left_out) text += "- " + l + "\n";
        report.paragraph(text);
    }
    report.heading("Contact sheet");
    if (sheet_error.empty() && !sheet.empty())
        report.image("garments.png", "Each garment from a file on the default avatar's walk (rows: flared skirt, wrap skirt, panel dress, "
                                     "cape), frames 60, 120, 180 and 240");
    else
        report.paragraph("Not rendered: " + (sheet_error.empty() ? std::string("no default avatar walk ran") : sheet_error) + ".");

    nlohmann::json j = nlohmann::json::array();
    for (const GarmentRun& r : runs) {
        nlohmann::json row = {{"character", r.character}, {"clip", r.clip}, {"kind", r.kind}, {"garment", r.garment}};
        if (!r.error.empty()) {
            row["error"] = r.error;
        } else {
            row["particles"] = r.particles;
            row["strain_p99"] = r.stats.strain_p99;
            row["strain_max"] = r.stats.strain_max;
            row["compression_min"] = r.stats.compression_min;
            row["penetration_after_m"] = r.stats.penetration_after_frame_m;
            row["rise_above_pins_m"] = r.stats.rise_above_pins_m;
            row["ms_p50"] = r.ms_p50;
            row["ms_p95"] = r.ms_p95;
        }
        row["within_contract"] = r.within();
        j.push_back(row);
    }
    return finish(report, options, {{"runs", j}, {"cost_per_particle_ratio", ratios}});
}

}  // namespace drape::bench
