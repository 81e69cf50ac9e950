// What every `drape bench NAME` shares: its options, the machine it ran on, medians,
// a Markdown report, a gnuplot PNG and the JSON file.
//
// A benchmark measures and reports; it never asserts a timing. It fails (non-zero exit)
// only when it cannot run: a missing asset, an output it cannot write, bad options.
// Everything it writes under the output folder is named after the benchmark
// (`<name>.md`, `<name>*.png`), so nothing else a user keeps there is touched.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "drape/components/garment.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/systems/cloth/garment_builder.hpp"

namespace drape::bench {

/// Options shared by every benchmark (`drape bench NAME [--json FILE] [--out DIR] ...`).
struct BenchOptions {
    std::string name;                          ///< The benchmark.
    std::filesystem::path json;                ///< Where to write the JSON; empty = none.
    std::filesystem::path out_dir = "docs/reports";
    int runs = 5;                              ///< Repeated runs; tables show medians.
    int threads = 1;                           ///< Worker threads (tbb::global_control).
    std::string command;                       ///< The command line that reproduces the run.
    std::string filter;                        ///< Comma-separated words a case's name must hold (benchmarks that list cases).
    /// Garment parameters (docs/scenes.md's table: name, value) given to every garment of the
    /// runs instead of the shipped values (`--garment-param NAME=VALUE`; motions and cut only).
    std::vector<std::pair<std::string, double>> garment_parameters;
    /// Where in its clip every case starts, s (`--start`; stability only).
    double start_s = 0;
    /// How the shipped integrator solves the warp springs (`--warp-solve`; motions and
    /// stability only).
    WarpSolve warp_solve = WarpSolve::rounds;
    /// The characters' body fit: FitOptions::thicken_thin_trunk_m (`--thicken-thin-trunk`;
    /// motions only; 0: none; unset: as shipped, default_thicken_thin_trunk_m).
    std::optional<double> thicken_thin_trunk_m;
    /// How the garments' skinned pins are bound (`--pin-weights`; motions only; none: as
    /// shipped, GarmentDescription::pin_weights).
    std::optional<PinWeights> pin_weights;
};

/// The machine and conditions a report was measured under.
struct Machine {
    std::string cpu_model;       ///< /proc/cpuinfo "model name".
    int logical_cpus = 0;        ///< Online CPUs (nproc).
    std::string loadavg_start;   ///< /proc/loadavg when the benchmark started.
    std::string compiler;
    std::string build;           ///< Build type and flags that matter for timing.
    std::string source_commit;   ///< `git rev-parse --short HEAD` of the source tree, if any.
    std::string date_utc;
};

[[nodiscard]] Machine describe_machine();
/// The name a scene and `--pin-weights` give `weights` ("nearest_vertex", "skin_surface").
[[nodiscard]] const char* pin_weights_name(PinWeights weights);

/// ", but NAME = VALUE, ..." for the settings `options` changes from the shipped ones
/// (garment parameters, the warp solve, the body fit's thickening); empty when none.
[[nodiscard]] std::string changed_parameters(const BenchOptions& options);
/// Current /proc/loadavg (first three fields), or "unavailable".
[[nodiscard]] std::string current_loadavg();

/// Median of samples (mean of the middle two for an even count); 0 for none.
[[nodiscard]] double median(std::vector<double> samples);

/// Milliseconds of wall time since `start` (steady clock).
[[nodiscard]] double elapsed_ms(std::int64_t start_ns);
[[nodiscard]] std::int64_t now_ns();

/// A target a report states and checks: met or missed, and by how much.
struct Target {
    std::string what;        ///< "simplified total per 1/60 s frame"
    std::string goal;        ///< "<= 0.1 ms"
    std::string measured;    ///< "0.083 ms"
    bool met = false;
    std::string margin;      ///< "17 % under" / "missed by 2.3x"
};

/// "x % under the target" or "missed by ..." for a measured value and an upper bound.
[[nodiscard]] Target upper_bound_target(std::string what, double measured, double bound,
                                        const std::string& unit, int decimals = 3);

/// Formats a number with a fixed count of decimals ("-" for non-finite).
[[nodiscard]] std::string fixed(double value, int decimals = 3);

/// One data block of a plot: columns separated by spaces, one row per line.
struct PlotData {
    std::string name;                         ///< Referred to as "$name" in the script.
    std::vector<std::vector<double>> rows;
};

/// A Markdown report, section by section.
class Report {
public:
    Report(std::string title, const BenchOptions& options, Machine machine);

    void heading(const std::string& text);               ///< A "## " heading.
    void paragraph(const std::string& text);
    void table(const std::vector<std::string>& header,
               const std::vector<std::vector<std::string>>& rows);
    void targets(const std::vector<Target>& targets);     ///< A table of targets.
    void image(const std::string& png_name, const std::string& alt);
    /// Says that a plot could not be made (e.g. gnuplot absent) and why.
    void missing_plot(const std::string& why);
    /// Renders a gnuplot plot into the output folder and adds it, or says why it could not.
    void plot(const std::string& png_name, const std::string& alt, const std::vector<PlotData>& data,
              const std::string& script, int width_px = 900, int height_px = 560);

    /// Writes `<out_dir>/<name>.md` (creating the folder); returns the path.
    [[nodiscard]] Result<std::filesystem::path> write() const;

private:
    std::string m_text;
    BenchOptions m_options;
    Machine m_machine;
};


/// Renders a gnuplot script to `<out_dir>/<png_name>` (pngcairo when available, png
/// otherwise). Data blocks are inlined as gnuplot datablocks. Returns an error when gnuplot
/// is absent or fails; the caller says so in the report and keeps the table.
[[nodiscard]] Result<void> plot(const std::filesystem::path& out_dir, const std::string& png_name,
                                const std::vector<PlotData>& data, const std::string& script,
                                int width_px = 900, int height_px = 560);

/// Writes JSON (indented) to a file; errors name the file.
[[nodiscard]] Result<void> write_json(const std::filesystem::path& file, const nlohmann::json& value);

/// The end of every benchmark: writes the report, and the JSON when --json was given.
[[nodiscard]] Result<void> finish(const Report& report, const BenchOptions& options, const nlohmann::json& json);

/// A registered benchmark.
struct Benchmark {
    std::string name;
    std::string summary;
    std::function<Result<void>(const BenchOptions&)> run;
};

/// Every benchmark `drape bench` knows, in the order `all` runs them.
[[nodiscard]] const std::vector<Benchmark>& benchmarks();

// The benchmarks (each in its own file).
[[nodiscard]] Result<void> run_table1(const BenchOptions& options);
[[nodiscard]] Result<void> run_error(const BenchOptions& options);
[[nodiscard]] Result<void> run_stability(const BenchOptions& options);
[[nodiscard]] Result<void> run_scale(const BenchOptions& options);
[[nodiscard]] Result<void> run_peers(const BenchOptions& options);
[[nodiscard]] Result<void> run_render(const BenchOptions& options);
[[nodiscard]] Result<void> run_soak(const BenchOptions& options);
[[nodiscard]] Result<void> run_quality(const BenchOptions& options);
[[nodiscard]] Result<void> run_motions(const BenchOptions& options);
[[nodiscard]] Result<void> run_garments(const BenchOptions& options);
[[nodiscard]] Result<void> run_cut(const BenchOptions& options);

}  // namespace drape::bench
