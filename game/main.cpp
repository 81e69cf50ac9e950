// The `drape` command: play the sample scene, inspect characters, run benchmarks.
#include <vector>

#include "game/commands.hpp"

int main(int argc, char** argv) {
    CLI::App app{"Drape: real-time physically based garments on skinned, walking characters"};
    app.require_subcommand(0, 1);
    drape::add_play_command(app);
    drape::add_inspect_command(app);
    drape::add_make_avatar_command(app);
#ifdef DRAPE_HAVE_BENCH
    drape::add_bench_command(app);
#endif
    // No subcommand: play the sample scene.
    std::vector<const char*> args(argv, argv + argc);
    if (argc == 1) args.push_back("play");
    try {
        app.parse(static_cast<int>(args.size()), args.data());
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }
    return drape::command_exit_code();
}
