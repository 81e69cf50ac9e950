// Report plumbing shared by the benchmarks: machine description, medians, Markdown,
// gnuplot and JSON output.
#include "bench/report.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <sstream>
#include <thread>

#include <unistd.h>

#include "drape/game/scene_description.hpp"
#include "drape/systems/character/ellipsoid_fit.hpp"
#include "drape/systems/cloth/garment_parameters.hpp"

namespace drape::bench {

namespace {

std::string read_first_line(const char* path) {
    std::ifstream in(path);
    std::string line;
    if (!in || !std::getline(in, line)) return {};
    return line;
}

/// Runs a shell command and returns its first line of output ("" on failure).
std::string command_output(const std::string& command) {
    std::FILE* pipe = ::popen(command.c_str(), "r");
    if (!pipe) return {};
    char buffer[256] = {};
    std::string out;
    if (std::fgets(buffer, sizeof buffer, pipe)) out = buffer;
    ::pclose(pipe);
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
    return out;
}

bool have_program(const std::string& program) {
    return !command_output("command -v " + program + " 2>/dev/null").empty();
}

}  // namespace

const char* pin_weights_name(PinWeights weights) {
    return weights == PinWeights::skin_surface ? "skin_surface" : "nearest_vertex";
}

std::string changed_parameters(const BenchOptions& options) {
    std::string text;
    for (const auto& [name, value] : options.garment_parameters)
        text += (text.empty() ? " but " : ", ") + name + " = " + parameter_number_text(value);
    if (options.warp_solve == WarpSolve::lines) text += (text.empty() ? " but " : ", ") + std::string("warp lines solved directly");
    if (options.thicken_thin_trunk_m && *options.thicken_thin_trunk_m != default_thicken_thin_trunk_m)
        text += (text.empty() ? " but " : ", ") +
                (*options.thicken_thin_trunk_m > 0
                     ? "trunk shells at most " + parameter_number_text(*options.thicken_thin_trunk_m) + " m thin thickened inward"
                     : std::string("no trunk shell thickened"));
    if (options.pin_weights && *options.pin_weights != GarmentDescription{}.pin_weights)
        text += (text.empty() ? " but " : ", ") + std::string("pins weighted by the ") +
                (*options.pin_weights == PinWeights::skin_surface ? "skin surface under them" : "nearest skin vertex");
    return text;
}

std::string current_loadavg() {
    std::string line = read_first_line("/proc/loadavg");
    if (line.empty()) return "unavailable";
    std::istringstream in(line);
    std::string a, b, c;
    in >> a >> b >> c;
    return a + " " + b + " " + c;
}

Machine describe_machine() {
    Machine m;
    std::ifstream cpuinfo("/proc/cpuinfo");
    for (std::string line; std::getline(cpuinfo, line);) {
        if (line.rfind("model name", 0) == 0) {
            auto colon = line.find(':');
            if (colon != std::string::npos) m.cpu_model = line.substr(colon + 2);
            break;
        }
    }
    if (m.cpu_model.empty()) m.cpu_model = "unknown CPU";
    long online = ::sysconf(_SC_NPROCESSORS_ONLN);
    m.logical_cpus = online > 0 ? static_cast<int>(online) : static_cast<int>(std::thread::hardware_concurrency());
    m.loadavg_start = current_loadavg();
    m.compiler = "g++ " __VERSION__;
#ifdef NDEBUG
    m.build = "Release (NDEBUG)";
#else
    m.build = "not Release (asserts on): timings are not representative";
#endif
#ifdef __AVX2__
    m.build += ", AVX2";
#endif
#ifdef __AVX512F__
    m.build += ", AVX-512";  // the same source runs its chaotic cases elsewhere on such a build (docs/cloth.md "Reproducibility")
#endif
#ifdef DRAPE_BENCH_SOURCE_DIR
    m.source_commit = command_output("git -C '" DRAPE_BENCH_SOURCE_DIR "' rev-parse --short HEAD 2>/dev/null");
#endif
    if (m.source_commit.empty()) m.source_commit = "unknown";
    std::time_t t = std::time(nullptr);
    char date[64];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
    m.date_utc = date;
    return m;
}

double median(std::vector<double> samples) {
    if (samples.empty()) return 0;
    std::sort(samples.begin(), samples.end());
    const std::size_t n = samples.size();
    return n % 2 ? samples[n / 2] : 0.5 * (samples[n / 2 - 1] + samples[n / 2]);
}

std::int64_t now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

double elapsed_ms(std::int64_t start_ns) { return static_cast<double>(now_ns() - start_ns) * 1e-6; }

std::string fixed(double value, int decimals) {
    if (!std::isfinite(value)) return "-";
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
    return buffer;
}

Target upper_bound_target(std::string what, double measured, double bound, const std::string& unit,
                          int decimals) {
    Target t;
    t.what = std::move(what);
    t.goal = "<= " + fixed(bound, decimals) + (unit.empty() ? "" : " " + unit);
    t.measured = fixed(measured, decimals) + (unit.empty() ? "" : " " + unit);
    t.met = std::isfinite(measured) && measured <= bound;
    if (!std::isfinite(measured)) {
        t.margin = "not measured";
    } else if (t.met) {
        t.margin = fixed(100.0 * (1.0 - measured / bound), 0) + " % under";
    } else {
        t.margin = "missed by " + fixed(measured - bound, decimals) + (unit.empty() ? "" : " " + unit);
        if (bound > 0) t.margin += " (" + fixed(measured / bound, 2) + "x the target)";
    }
    return t;
}

Report::Report(std::string title, const BenchOptions& options, Machine machine)
    : m_options(options), m_machine(std::move(machine)) {
    m_text = "# " + title + "\n\n";
    m_text += "Generated by `" + options.command + "` on " + m_machine.date_utc +
              " (source " + m_machine.source_commit + "). Do not edit: rerun the command.\n\n";
    m_text += "Machine: " + m_machine.cpu_model + ", " + std::to_string(m_machine.logical_cpus) +
              " logical CPUs (nproc), shared with other work; load average at start " +
              m_machine.loadavg_start + ". " + m_machine.compiler + ", " + m_machine.build + ". " +
              "Times are medians over " + std::to_string(options.runs) + " runs unless stated.\n\n";
}

void Report::heading(const std::string& text) { m_text += "## " + text + "\n\n"; }

void Report::paragraph(const std::string& text) { m_text += text + "\n\n"; }

void Report::table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
    auto line = [&](const std::vector<std::string>& cells) {
        m_text += "|";
        for (const auto& c : cells) m_text += " " + c + " |";
        m_text += "\n";
    };
    line(header);
    m_text += "|";
    for (std::size_t i = 0; i < header.size(); ++i) m_text += "---|";
    m_text += "\n";
    for (const auto& row : rows) line(row);
    m_text += "\n";
}

void Report::targets(const std::vector<Target>& targets) {
    std::vector<std::vector<std::string>> rows;
    for (const auto& t : targets)
        rows.push_back({t.what, t.goal, t.measured, t.met ? "met" : "**missed**", t.margin});
    table({"target", "goal", "measured", "status", "margin"}, rows);
}

void Report::image(const std::string& png_name, const std::string& alt) {
    m_text += "![" + alt + "](" + png_name + ")\n\n";
}

void Report::missing_plot(const std::string& why) {
    m_text += "_No plot: " + why + ". The table above holds the same data._\n\n";
}

Result<std::filesystem::path> Report::write() const {
    std::error_code ec;
    std::filesystem::create_directories(m_options.out_dir, ec);
    if (ec) return fail(m_options.out_dir.string() + ": cannot create folder: " + ec.message());
    const auto path = m_options.out_dir / (m_options.name + ".md");
    std::ofstream out(path, std::ios::trunc);
    if (!out) return fail(path.string() + ": cannot open for writing");
    out << m_text << "Load average at the end: " << current_loadavg() << ".\n";
    if (!out) return fail(path.string() + ": write failed");
    return path;
}

Result<void> plot(const std::filesystem::path& out_dir, const std::string& png_name,
                  const std::vector<PlotData>& data, const std::string& script, int width_px, int height_px) {
    if (!have_program("gnuplot")) return fail("gnuplot is not installed (Debian package gnuplot-nox)");
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec) return fail(out_dir.string() + ": cannot create folder: " + ec.message());
    const bool cairo = !command_output("gnuplot -e 'set terminal' 2>&1 | grep -w pngcairo").empty();

    std::ostringstream text;
    text.precision(9);
    if (cairo)
        text << "set terminal pngcairo size " << width_px << "," << height_px << " font 'sans,10'\n";
    else
        text << "set terminal png size " << width_px << "," << height_px << "\n";
    text << "set output '" << (out_dir / png_name).string() << "'\n";
    for (const auto& block : data) {
        text << "$" << block.name << " << EOD\n";
        for (const auto& row : block.rows) {
            for (std::size_t i = 0; i < row.size(); ++i) text << (i ? " " : "") << row[i];
            text << "\n";
        }
        text << "EOD\n";
    }
    text << script << "\n";

    auto script_file = std::filesystem::temp_directory_path(ec) /
                       ("drape-bench-" + std::to_string(::getpid()) + "-" + png_name + ".gp");
    if (ec) return fail("no temporary folder for the gnuplot script: " + ec.message());
    {
        std::ofstream out(script_file, std::ios::trunc);
        if (!out) return fail(script_file.string() + ": cannot write gnuplot script");
        out << text.str();
    }
    const std::string command = "gnuplot '" + script_file.string() + "' 2>&1";
    std::FILE* pipe = ::popen(command.c_str(), "r");
    std::string output;
    if (pipe) {
        char buffer[512];
        while (std::fgets(buffer, sizeof buffer, pipe)) output += buffer;
    }
    const int status = pipe ? ::pclose(pipe) : -1;
    std::filesystem::remove(script_file, ec);
    if (status != 0) return fail("gnuplot failed on " + png_name + ": " + output);
    return {};
}

Result<void> write_json(const std::filesystem::path& file, const nlohmann::json& value) {
    if (file.has_parent_path()) {
        std::error_code ec;
        std::filesystem::create_directories(file.parent_path(), ec);
        if (ec) return fail(file.string() + ": cannot create folder: " + ec.message());
    }
    std::ofstream out(file, std::ios::trunc);
    if (!out) return fail(file.string() + ": cannot open for writing");
    out << value.dump(2) << "\n";
    if (!out) return fail(file.string() + ": write failed");
    return {};
}

void Report::plot(const std::string& png_name, const std::string& alt, const std::vector<PlotData>& data,
                  const std::string& script, int width_px, int height_px) {
    if (auto ok = bench::plot(m_options.out_dir, png_name, data, script, width_px, height_px); ok)
        image(png_name, alt);
    else
        missing_plot(ok.error().message);
}

Result<void> finish(const Report& report, const BenchOptions& options, const nlohmann::json& json) {
    if (auto path = report.write(); !path) return fail(path.error().message);
    if (!options.json.empty())
        if (auto ok = write_json(options.json, json); !ok) return fail(ok.error().message);
    return {};
}

}  // namespace drape::bench
