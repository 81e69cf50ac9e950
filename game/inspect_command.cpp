// `drape inspect FILE`: what a character file holds.
#include <cstdio>

#include "game/commands.hpp"

namespace drape {

void add_inspect_command(CLI::App& app) {
    CLI::App* inspect = app.add_subcommand("inspect", "Print what a character file holds");
    inspect->callback([] {
        std::fputs("drape inspect: character import is not built yet\n", stderr);
        command_exit_code() = 1;
    });
}

}  // namespace drape
