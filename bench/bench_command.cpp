// `drape bench NAME [--json FILE] [--out DIR] [--runs N] [--threads N]`: runs a benchmark
// and writes its report (docs/reports/NAME.md and a PNG plot) and, on request, its JSON.
// `drape bench all` refreshes every report; with --json it takes a folder and writes
// NAME.json there for each benchmark.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <tbb/global_control.h>

#include "bench/report.hpp"
#include "drape/game/commands.hpp"
#include "drape/systems/character/ellipsoid_fit.hpp"
#include "drape/systems/cloth/garment_parameters.hpp"

namespace drape {

namespace bench {

const std::vector<Benchmark>& benchmarks() {
    static const std::vector<Benchmark> list = {
        {"table1", "the paper's Table 1: model (classic, simplified) x collision (brute force, candidate lists) at equal substeps", run_table1},
        {"error", "error against run time over model x substeps x iterations x collision; analytic references", run_error},
        {"stability", "stiffness x frame time x motion x garment, with and without automatic substeps", run_stability},
        {"scale", "garment size, walker count and threads; microseconds per particle per frame", run_scale},
        {"peers", "Bullet soft-body cloth against Drape on the same skirt and ellipsoids", run_peers},
        {"render", "off-screen rendering at 1280x720, ms per frame", run_render},
        {"soak", "the sample scene walking for an hour of simulated time: drift per minute", run_soak},
        {"quality", "after-frame strain, penetration, cost and shape against a converged reference, per garment x model x character", run_quality},
        {"motions", "every character x each clip a garment is played on and root motions x garment x model x start, judged by the contract", run_motions},
        {"garments", "garments from files (four cut garments) on every character's walk and run, judged by the contract, cost per particle", run_garments},
        {"cut", "the hem's radius on a still body, simplified against classic, per character and garment", run_cut},
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
    if (!o.filter.empty()) c += " --filter '" + o.filter + "'";
    for (const auto& [name, value] : o.garment_parameters) c += " --garment-param " + name + "=" + parameter_number_text(value);
    if (o.start_s > 0) c += " --start " + parameter_number_text(o.start_s);
    if (o.warp_solve == WarpSolve::lines) c += " --warp-solve lines";
    if (o.thicken_thin_trunk_m) c += " --thicken-thin-trunk " + parameter_number_text(*o.thicken_thin_trunk_m);
    if (o.pin_weights) c += std::string(" --pin-weights ") + bench::pin_weights_name(*o.pin_weights);
    return c;
}

// `--garment-param NAME=VALUE`: a row of the garment parameter table and a value in its
// range; else one line naming the option, the parameter and why.
Result<std::pair<std::string, double>> garment_param(const std::string& text) {
    const std::size_t eq = text.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
        return fail("--garment-param '" + text + "': give NAME=VALUE (drape scene-parameters lists the names)");
    const std::string name = text.substr(0, eq), number = text.substr(eq + 1);
    const GarmentParameterSpec* spec = find_garment_parameter(name);
    if (spec == nullptr)
        return fail("--garment-param " + name + ": no garment parameter of that name (drape scene-parameters lists them)");
    char* end = nullptr;
    const double value = std::strtod(number.c_str(), &end);
    if (end != number.c_str() + number.size() || !spec->range.contains(value) ||
        (spec->kind == ParameterKind::integer && value != std::floor(value)))
        return fail("--garment-param " + name + ": must be in " + spec->range_text() + ", got '" + number + "'");
    return std::pair{name, value};
}

// Nothing a user wrote is replaced (game/output_files.hpp): an existing --json file needs
// --overwrite, and so does a NAME.md in --out that is not a report this command wrote.
std::string refused_output(const bench::BenchOptions& o, bool overwrite) {
    std::error_code ec;
    if (overwrite) return {};
    if (!o.json.empty() && std::filesystem::exists(o.json, ec))
        return "--json: " + o.json.string() + " already exists (add --overwrite to replace it)";
    const auto report = o.out_dir / (o.name + ".md");
    if (std::filesystem::exists(report, ec)) {
        std::ifstream in(report);
        std::string title, blank, generated;
        std::getline(in, title);
        std::getline(in, blank);
        std::getline(in, generated);
        if (generated.rfind("Generated by `drape bench " + o.name, 0) != 0)
            return "--out: " + report.string() + " exists and is not a drape bench report (add --overwrite to replace it)";
    }
    return {};
}

}  // namespace

void add_bench_command(CLI::App& app) {
    struct Cli {
        std::string name;
        std::string json;
        std::string out = "docs/reports";
        int runs = 5;
        int threads = 1;
        bool overwrite = false;
        std::string filter;
        std::vector<std::string> garment_params;
        double start_s = 0;
        std::string warp_solve;
        double thicken_thin_trunk_m = default_thicken_thin_trunk_m;
        std::string pin_weights;
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
    command->add_option("--filter", cli->filter, "Only the cases whose name holds every comma-separated word (motions, garments, cut, stability)");
    command->add_option("--garment-param", cli->garment_params,
                        "NAME=VALUE: a garment parameter (docs/scenes.md) for every garment instead of the shipped value (motions, cut); "
                        "repeatable");
    command->add_option("--start", cli->start_s, "Seconds into the clip where every case starts (stability; default 0)")
        ->check(CLI::Range(0.0, 1000.0));
    command->add_option("--warp-solve", cli->warp_solve,
                        "The shipped solver's warp springs: rounds (default) or lines (motions, stability; docs/cloth.md)")
        ->check(CLI::IsMember({"rounds", "lines"}));
    command->add_option("--thicken-thin-trunk", cli->thicken_thin_trunk_m,
                        "M: the body fit thickens trunk shells at most M thin inward to the thick ones (motions; 0: none; "
                        "default: as shipped, " + parameter_number_text(default_thicken_thin_trunk_m) + "; docs/cloth.md)")
        ->check(CLI::Range(0.0, 0.1));
    command->add_option("--pin-weights", cli->pin_weights,
                        "Skinned pins take the nearest skin vertex's weights or the skin's where they sit (motions; default: as "
                        "shipped; docs/cloth.md)")
        ->check(CLI::IsMember({"nearest_vertex", "skin_surface"}));
    command->add_flag("--overwrite", cli->overwrite, "Replace an existing --json file or a NAME.md this command did not write");
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
            command_exit_code() = exit_bad_input;
            return;
        }
        std::vector<std::pair<std::string, double>> garment_parameters;
        for (const std::string& text : cli->garment_params) {
            auto parameter = garment_param(text);
            if (!parameter) {
                std::fprintf(stderr, "drape bench: %s\n", parameter.error().message.c_str());
                command_exit_code() = exit_bad_input;
                return;
            }
            garment_parameters.push_back(*parameter);
        }
        // Options only some benchmarks take: {given, option, the benchmarks taking it}.
        const struct {
            bool given;
            const char* option;
            std::vector<std::string> takers;
        } limited[] = {{!garment_parameters.empty(), "--garment-param", {"motions", "cut"}},
                       {cli->start_s > 0, "--start", {"stability"}},
                       {!cli->warp_solve.empty(), "--warp-solve", {"motions", "stability"}},
                       {command->count("--thicken-thin-trunk") > 0, "--thicken-thin-trunk", {"motions"}},
                       {!cli->pin_weights.empty(), "--pin-weights", {"motions"}}};
        for (const auto& l : limited) {
            if (!l.given || std::find(l.takers.begin(), l.takers.end(), cli->name) != l.takers.end()) continue;
            std::string which = "the " + l.takers[0];
            for (std::size_t i = 1; i < l.takers.size(); ++i) which += (i + 1 == l.takers.size() ? " and " : ", ") + l.takers[i];
            std::fprintf(stderr, "drape bench: %s: only %s benchmark%s take%s it\n", l.option, which.c_str(),
                         l.takers.size() > 1 ? "s" : "", l.takers.size() > 1 ? "" : "s");
            command_exit_code() = exit_bad_input;
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
        std::vector<bench::BenchOptions> all_options;
        for (const auto* b : selected) {
            bench::BenchOptions options;
            options.name = b->name;
            options.out_dir = cli->out;
            options.runs = cli->runs;
            options.threads = cli->threads;
            options.filter = cli->filter;
            options.garment_parameters = garment_parameters;
            options.start_s = cli->start_s;
            options.warp_solve = cli->warp_solve == "lines" ? WarpSolve::lines : WarpSolve::rounds;
            if (command->count("--thicken-thin-trunk") > 0) options.thicken_thin_trunk_m = cli->thicken_thin_trunk_m;
            if (!cli->pin_weights.empty())
                options.pin_weights = cli->pin_weights == "skin_surface" ? PinWeights::skin_surface : PinWeights::nearest_vertex;
            if (!cli->json.empty())
                options.json = cli->name == "all" ? std::filesystem::path(cli->json) / (b->name + ".json")
                                                  : std::filesystem::path(cli->json);
            options.command = quoted_command(cli->runs, cli->threads, options, runs_set, threads_set);
            if (const std::string refused = refused_output(options, cli->overwrite); !refused.empty()) {
                std::fprintf(stderr, "drape bench: %s\n", refused.c_str());
                command_exit_code() = exit_bad_input;
                return;
            }
            all_options.push_back(std::move(options));
        }
        int failures = 0;
        for (std::size_t i = 0; i < selected.size(); ++i) {
            const auto* b = selected[i];
            const bench::BenchOptions& options = all_options[i];
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
