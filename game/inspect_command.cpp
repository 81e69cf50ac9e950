// `drape inspect FILE [--json]`: what a character file holds — meshes, vertices, bones,
// clips with durations, fitted ellipsoids and their coverage, height in metres.
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "drape/engine/assets/character_import.hpp"
#include "drape/game/commands.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/character_report.hpp"

namespace drape {

void add_inspect_command(CLI::App& app) {
    struct Options {
        std::string file;
        bool json = false;
        std::optional<double> scale;
        std::optional<double> height_m;
        bool allow_static = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* inspect = app.add_subcommand("inspect", "Print what a character file holds (glTF, FBX, COLLADA)");
    inspect->add_option("file", o->file, "Character file")->required();
    inspect->add_flag("--json", o->json, "Print JSON instead of text");
    inspect->add_option("--scale", o->scale, "File units -> metres (default: the file's units, or by height)");
    inspect->add_option("--height", o->height_m, "Scale the character to this height in metres");
    inspect->add_flag("--allow-static", o->allow_static, "Accept a character without animation clips");
    inspect->callback([o] {
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
