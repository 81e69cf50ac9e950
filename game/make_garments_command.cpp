// `drape make-garments --out DIR [--character FILE]`: cuts the garments of
// game/garment_patterns.hpp for a character (default: the sample scene's avatar) and writes
// each as DIR/NAME.glb. Never overwrites a file. assets/garments/ is its output for the
// default avatar.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>

#include "drape/game/commands.hpp"
#include "drape/game/garment_patterns.hpp"
#include "drape/game/sample_scene.hpp"

namespace drape {

void add_make_garments_command(CLI::App& app) {
    struct Options {
        std::string out, character;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("make-garments", "Cut a flared skirt, a wrap skirt, a panel dress and a cape for a character, as glTF");
    command->add_option("--out", o->out, "Folder to write NAME.glb into (created; no file overwritten)")->required()->check(not_empty());
    command->add_option("--character", o->character, "Character file (default: the sample scene's avatar)")->check(not_empty());
    command->callback([o] {
        auto error = [](const std::string& message) { command_error("make-garments", message); };
        SceneDescription scene = sample_scene();
        if (!o->character.empty()) use_character_file(scene, o->character);
        auto garments = cut_garments(scene);
        if (!garments) return error(garments.error().message);
        const std::filesystem::path dir = o->out;
        for (const CutGarment& g : *garments)
            if (std::error_code ec; std::filesystem::exists(dir / (g.name + ".glb"), ec))
                return error("--out: " + (dir / (g.name + ".glb")).string() + ": exists (not overwritten)");
        std::error_code ec;
        std::filesystem::create_directories(dir, ec);
        if (ec) return error("--out: " + o->out + ": " + ec.message());
        for (const CutGarment& g : *garments) {
            if (auto ok = write_garment_mesh(dir / (g.name + ".glb"), g.mesh); !ok) return error("--out: " + ok.error().message);
            std::printf("drape make-garments: wrote %s (%d panel%s, %s, %zu vertices)\n", (dir / (g.name + ".glb")).c_str(), g.panels,
                        g.panels == 1 ? "" : "s", g.closed ? "closed" : "open", g.mesh.vertex_count());
        }
    });
}

}  // namespace drape
