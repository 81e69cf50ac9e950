// `drape bench NAME [--json FILE] [--out DIR] [--runs N] [--threads N]`: runs a benchmark
// and writes its report (docs/reports/NAME.md and a PNG plot) and, on request, its JSON.
// `drape bench all` refreshes every report; with --json it takes a folder and writes
// NAME.json there for each benchmark.
#include <cstdio>
#include <memory>
#include <string>

#include <tbb/global_control.h>

#include "bench/report.hpp"
#include "game/commands.hpp"

namespace drape {

namespace bench {

const std::vector<Benchmark>& benchmarks() {
    static const std::vector<Benchmark> list = {
        {"table1", "the paper's Table 1: classic + brute force vs simplified + candidate lists", run_table1},
        {"error", "error against run time over model x substeps x iterations x collision; analytic references", run_error},
        {"stability", "stiffness x frame time x motion x garment, with and without automatic substeps", run_stability},
        {"scale", "garment size, walker count and threads; microseconds per particle per frame", run_scale},
        {"peers", "Bullet soft-body cloth against Drape on the same skirt and ellipsoids", run_peers},
        {"render", "off-screen rendering at 1280x720, ms per frame", run_render},
        {"soak", "the sample scene walking for an hour of simulated time: drift per minute", run_soak},
    };
    return list;
}

}  // namespace bench

namespace {

std::string quoted_command(int runs, int threads, const bench::BenchOptions& o, bool runs_set, bool threads_set) {
    std::string c = "drape bench " + o.name;
    if (o.out_dir != "docs/reports") c += " --out " + o.out_dir.string();
    if (runs_set) c += " --runs " + std::to_string(runs);
    if (threads_set) c += " --threads " + std::to_string(threads);
    return c;
}

}  // namespace

void add_bench_command(CLI::App& app) {
    struct Cli {
        std::string name;
        std::string json;
        std::string out = "docs/reports";
        int runs = 5;
        int threads = 1;
    };
    auto cli = std::make_shared<Cli>();
    std::string names;
    for (const auto& b : bench::benchmarks()) names += (names.empty() ? "" : ", ") + b.name;
    names += ", all";

    CLI::App* command = app.add_subcommand("bench", "Run a benchmark and write its report under docs/reports");
    command->add_option("name", cli->name, "Benchmark: " + names)->required();
    command->add_option("--json", cli->json, "Write the results as JSON to FILE (with 'all': a folder, one NAME.json each)");
    command->add_option("--out", cli->out, "Folder for the Markdown reports and plots (default docs/reports)");
    command->add_option("--runs", cli->runs, "Repeated runs; tables show medians (default 5)")->check(CLI::Range(1, 1000));
    command->add_option("--threads", cli->threads, "Worker threads for parallel systems (default 1)")->check(CLI::Range(1, 256));
    command->footer("Benchmarks: " + names + ". Each writes NAME.md and NAME*.png in the output folder "
                    "and never asserts a timing; it fails only when it cannot run.");

    command->callback([cli, command] {
        std::vector<const bench::Benchmark*> selected;
        for (const auto& b : bench::benchmarks())
            if (cli->name == "all" || cli->name == b.name) selected.push_back(&b);
        if (selected.empty()) {
            std::string known;
            for (const auto& b : bench::benchmarks()) known += " " + b.name;
            std::fprintf(stderr, "drape bench: no benchmark named '%s' (known:%s all)\n", cli->name.c_str(), known.c_str());
            command_exit_code() = 2;
            return;
        }
        const bool runs_set = command->count("--runs") > 0;
        const bool threads_set = command->count("--threads") > 0;
        // --threads caps every world (tbb::global_control); without it each benchmark sets
        // its worlds' threads itself (1 by default; `scale` compares 1 and 2).
        std::unique_ptr<tbb::global_control> threads;
        if (threads_set)
            threads = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                            static_cast<std::size_t>(cli->threads));
        int failures = 0;
        for (const auto* b : selected) {
            bench::BenchOptions options;
            options.name = b->name;
            options.out_dir = cli->out;
            options.runs = cli->runs;
            options.threads = cli->threads;
            if (!cli->json.empty())
                options.json = cli->name == "all" ? std::filesystem::path(cli->json) / (b->name + ".json")
                                                  : std::filesystem::path(cli->json);
            options.command = quoted_command(cli->runs, cli->threads, options, runs_set, threads_set);
            std::fprintf(stderr, "drape bench %s: %s\n", b->name.c_str(), b->summary.c_str());
            const auto start = bench::now_ns();
            if (auto ok = b->run(options); !ok) {
                std::fprintf(stderr, "drape bench %s: %s\n", b->name.c_str(), ok.error().message.c_str());
                ++failures;
                continue;
            }
            std::fprintf(stderr, "drape bench %s: wrote %s in %.1f s\n", b->name.c_str(),
                         (options.out_dir / (b->name + ".md")).c_str(), bench::elapsed_ms(start) * 1e-3);
        }
        command_exit_code() = failures ? 1 : 0;
    });
}

}  // namespace drape
