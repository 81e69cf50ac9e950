// `drape bench NAME`: runs a benchmark and writes its report.
#include <cstdio>
#include <string>

#include "game/commands.hpp"

namespace drape {

void add_bench_command(CLI::App& app) {
    auto name = std::make_shared<std::string>();
    CLI::App* bench = app.add_subcommand("bench", "Run a benchmark and write its report");
    bench->add_option("name", *name, "Benchmark name")->required();
    bench->callback([name] {
        std::fprintf(stderr, "drape bench: no benchmark named '%s'\n", name->c_str());
        command_exit_code() = 2;
    });
}

}  // namespace drape
