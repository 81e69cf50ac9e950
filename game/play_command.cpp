// `drape play`: builds a scene, runs it for a number of frames and prints the frame budget.
#include <cstdio>
#include <string>

#include "engine/core/registry.hpp"
#include "engine/core/scheduler.hpp"
#include "game/commands.hpp"

namespace drape {

int& command_exit_code() {
    static int code = 0;
    return code;
}

void add_play_command(CLI::App& app) {
    struct Options {
        int frames = 240;
        std::string trace;
    };
    auto options = std::make_shared<Options>();
    CLI::App* play = app.add_subcommand("play", "Play a scene (default: the sample scene) and print the frame budget");
    play->add_option("--frames", options->frames, "Frames to play")->check(CLI::Range(1, 10'000'000));
    play->add_option("--trace", options->trace, "Write Chrome trace event JSON to FILE");
    play->callback([options] {
        Registry registry;
        Scheduler scheduler;
        for (int frame = 0; frame < options->frames; ++frame) {
            if (auto report = scheduler.tick(registry, 1.0 / 60.0); !report) {
                std::fprintf(stderr, "drape play: %s\n", report.error().message.c_str());
                command_exit_code() = 1;
                return;
            }
        }
        std::fputs(scheduler.profiler().table().c_str(), stdout);
        if (!options->trace.empty()) {
            if (auto ok = scheduler.profiler().write_trace(options->trace); !ok) {
                std::fprintf(stderr, "drape play: %s\n", ok.error().message.c_str());
                command_exit_code() = 1;
            }
        }
    });
}

}  // namespace drape
