// The `drape` command: play the sample scene, inspect characters, run benchmarks.
// `drape --version` prints the project version (CMakeLists.txt).
// Exit codes (every subcommand): 0 done, 1 bad input or a failed run (game/commands.hpp).
#include <string>
#include <vector>

#include "drape/game/commands.hpp"

int main(int argc, char** argv) {
    CLI::App app{"Drape: real-time physically based garments on skinned, walking characters"};
    app.require_subcommand(0, 1);
    app.set_version_flag("--version", std::string("drape ") + DRAPE_VERSION, "Print Drape's version and exit");
    drape::add_play_command(app);
    drape::add_inspect_command(app);
    drape::add_make_avatar_command(app);
    drape::add_export_motion_command(app);
    drape::add_export_garment_command(app);
    drape::add_make_garments_command(app);
#ifdef DRAPE_HAVE_BENCH
    drape::add_bench_command(app);
#endif
    drape::add_scene_parameters_command(app);
    // No subcommand: play the sample scene.
    std::vector<const char*> args(argv, argv + argc);
    if (argc == 1) args.push_back("play");
    return drape::run_command_line(app, static_cast<int>(args.size()), args.data());
}
