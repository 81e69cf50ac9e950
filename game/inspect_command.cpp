// `drape inspect FILE [--json]`: what a character file holds — meshes, vertices, bones,
// clips with durations, fitted ellipsoids and their coverage, height in metres.
// `drape inspect --garment FILE[:MESH]`: a garment file's mesh, its pins and the grid it
// gives (panels, seams, particles; docs/garments.md).
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "drape/engine/assets/character_import.hpp"
#include "drape/engine/assets/garment_file.hpp"
#include "drape/game/commands.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/character_report.hpp"
#include "drape/systems/cloth/garment_from_mesh.hpp"

namespace drape {

void add_inspect_command(CLI::App& app) {
    struct Options {
        std::string file, garment;
        bool json = false;
        std::optional<double> scale;
        std::optional<double> height_m;
        bool allow_static = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* inspect = app.add_subcommand("inspect", "Print what a character file holds (glTF, FBX, COLLADA)");
    inspect->add_option("file", o->file, "Character file");
    inspect->add_option("--garment", o->garment, "A garment file (FILE[:MESH]): its mesh, panels, seams, grid and pins (docs/garments.md)")
        ->check(not_empty());
    inspect->add_flag("--json", o->json, "Print JSON instead of text");
    inspect->add_option("--scale", o->scale, "File units -> metres (default: the file's units, or by height)");
    inspect->add_option("--height", o->height_m, "Scale the character to this height in metres");
    inspect->add_flag("--allow-static", o->allow_static, "Accept a character without animation clips");
    inspect->callback([o] {
        if (!o->garment.empty()) {
            if (!o->file.empty()) { command_error("inspect", "give a character file or --garment, not both"); return; }
            const auto [file, name] = split_garment_reference(o->garment);
            auto mesh = import_garment_mesh(file, name);
            if (!mesh) { command_error("inspect", mesh.error().message); return; }
            const auto held = mesh->pin.size() == 0 ? -1 : static_cast<long>((mesh->pin.array() >= Real(0.5)).count());
            std::printf("garment: %s, mesh '%s'\n", file.c_str(), mesh->name.c_str());
            std::printf("mesh: %zu vertices, %zu triangles, UVs: %s, pins painted (COLOR_0): %s\n", mesh->vertex_count(),
                        mesh->indices.size() / 3, mesh->uvs.cols() ? "yes" : "none",
                        held < 0 ? "none (the higher edge is held)" : (std::to_string(held) + " vertices held").c_str());
            if (mesh->base_color.empty())
                std::printf("texture: none (drawn in the garment's colour)\n");
            else
                std::printf("texture: base colour %dx%d, by the UVs, repeated\n", mesh->base_color.width, mesh->base_color.height);
            if (mesh->uvs.cols() != mesh->positions.cols()) {
                auto pattern = derive_pattern(*mesh, "pattern");
                if (!pattern) { command_error("inspect", pattern.error().message); return; }
                std::printf("pattern: %s\n", pattern->c_str());
            }
            auto grid = grid_from_mesh(*mesh, {}, "grid");
            if (!grid) { command_error("inspect", grid.error().message); return; }
            std::printf("grid: %s\n", grid->how.c_str());
            std::printf("particles: %d (%d lines x %d rows; one line in %d integrated, method §3.2)\n",
                        grid->grid.warp_lines * grid->grid.particles_per_line, grid->grid.warp_lines, grid->grid.particles_per_line,
                        grid->grid.weft_stride);
            return;
        }
        if (o->file.empty()) { command_error("inspect", "give a character file (or --garment FILE)"); return; }
        ImportOptions options;
        options.scale = o->scale;
        options.height_m = o->height_m;
        options.require_animation = !o->allow_static;
        auto character = import_character(o->file, options);
        if (!character) {
            command_error("inspect", character.error().message);
            return;
        }
        for (const std::string& warning : (*character)->warnings) std::fprintf(stderr, "drape inspect: warning: %s\n", warning.c_str());
        auto body = fit_character_body(**character);
        if (!body) {
            std::fprintf(stderr, "drape inspect: %s\n", body.error().message.c_str());
            command_exit_code() = 1;
            return;
        }
        const CoverageReport coverage = rest_pose_coverage(**character, *body);
        const std::string report = o->json ? character_report_json(**character, *body, coverage)
                                           : character_report_text(**character, *body, coverage);
        std::fputs(report.c_str(), stdout);
    });
}

}  // namespace drape
