// `drape scene-parameters`: the garment parameters a scene file accepts, printed as the
// Markdown table of docs/scenes.md. The table is generated from the cloth module's
// parameter table (systems/cloth/garment_parameters.hpp); a test fails when the copy in
// docs/scenes.md differs from this output.
#include <cstdio>

#include "drape/game/commands.hpp"
#include "drape/game/scene_garment_parameters.hpp"

namespace drape {

void add_scene_parameters_command(CLI::App& app) {
    CLI::App* command = app.add_subcommand(
        "scene-parameters", "Print the garment parameters a scene file accepts (the Markdown table of docs/scenes.md)");
    command->callback([] { std::fputs(garment_parameters_markdown().c_str(), stdout); });
}

}  // namespace drape
