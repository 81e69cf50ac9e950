// The `drape` command line: exit status and errors, value checks with Drape-style messages,
// and one line per command-line error (CLI11 prints two and exits 105-ish codes of its own).

// GCC 12 with the sanitizers warns inside libstdc++'s <regex> (the std::function in its
// automaton's states: -Wmaybe-uninitialized, a false positive); the standard headers are
// read with that warning off.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <sstream>
#include <regex>
#include <string>
#include <vector>
#pragma GCC diagnostic pop

#include "drape/game/command_line.hpp"

namespace drape {
namespace {

// "1", "0.5", "1000", "1e-07": the shortest text that reads back.
std::string number_text(double v) {
    if (std::isfinite(v) && v == std::trunc(v) && std::abs(v) < 1e15) return std::to_string(static_cast<long long>(v));
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.17g", v);
    for (int digits = 1; digits <= 17; ++digits) {
        char shorter[32];
        std::snprintf(shorter, sizeof shorter, "%.*g", digits, v);
        if (std::strtod(shorter, nullptr) == v) return shorter;
    }
    return buffer;
}

// CLI11's own texts for checks Drape did not write (CLI::Range, CLI::IsMember in other
// commands), in Drape's words.
std::string reword(const std::string& message) {
    static const std::regex range(R"(^(\S+): Value (.*) not in range (\S+) to (\S+)$)");
    static const std::regex member(R"(^(\S+): (.*) not in \{(.*)\}$)");
    static const std::regex missing(R"(^(\S+): \d+ required .+ missing$)");
    std::smatch m;
    auto trimmed = [](const std::string& number) { return number_text(std::strtod(number.c_str(), nullptr)); };
    if (std::regex_match(message, m, range))
        return m[1].str() + ": must be in [" + trimmed(m[3]) + ", " + trimmed(m[4]) + "], got " + m[2].str();
    if (std::regex_match(message, m, member))
        return m[1].str() + ": must be one of " + std::regex_replace(m[3].str(), std::regex(","), ", ") + ", got \"" + m[2].str() + "\"";
    if (std::regex_match(message, m, missing)) return m[1].str() + ": needs a value";
    static const std::regex repeated(R"(^(\S+): At Most 1 required but received (\d+)$)");
    if (std::regex_match(message, m, repeated)) return m[1].str() + ": given " + m[2].str() + " times; give it once";
    return message;
}

std::string one_line(const CLI::ParseError& e, const CLI::App& app, bool top_level) {
    std::string message = e.what();
    if (dynamic_cast<const CLI::ExtrasError*>(&e) != nullptr) {
        // "The following argument(s) was/were not expected: bar --foo" (in reverse order).
        // The first unknown option is named, else the first stray argument.
        const auto colon = message.find(": ");
        std::istringstream extras(colon == std::string::npos ? message : message.substr(colon + 2));
        std::vector<std::string> args{std::istream_iterator<std::string>(extras), std::istream_iterator<std::string>()};
        std::reverse(args.begin(), args.end());
        const auto option = std::find_if(args.begin(), args.end(), [](const std::string& a) { return a.starts_with('-'); });
        if (option != args.end()) return *option + ": unknown option (--help lists the options)";
        const std::string first = args.empty() ? std::string("?") : args.front();
        if (top_level) {
            std::string commands;
            for (const CLI::App* sub : app.get_subcommands({})) commands += (commands.empty() ? "" : ", ") + sub->get_name();
            return first + ": no such command (commands: " + commands + ")";
        }
        return first + ": unexpected argument (--help lists the options)";
    }
    if (dynamic_cast<const CLI::RequiredError*>(&e) != nullptr && message.ends_with(" is required"))
        return message.substr(0, message.size() - 12) + ": missing (a required argument; --help shows the usage)";
    if (dynamic_cast<const CLI::ConversionError*>(&e) != nullptr) {
        static const std::regex convert(R"(^Could not convert: (\S+) = (.*)$)");
        std::smatch m;
        if (std::regex_match(message, m, convert)) return m[1].str() + ": not a valid value, got \"" + m[2].str() + "\"";
    }
    std::replace(message.begin(), message.end(), '\n', ' ');
    return reword(message);
}

}  // namespace

int& command_exit_code() {
    static int code = 0;
    return code;
}

int command_error(std::string_view command, const std::string& message) {
    std::fprintf(stderr, "drape %.*s: %s\n", static_cast<int>(command.size()), command.data(), message.c_str());
    command_exit_code() = exit_bad_input;
    return exit_bad_input;
}

CLI::Validator integer_in(long long min, long long max) {
    const std::string range = "[" + std::to_string(min) + ", " + std::to_string(max) + "]";
    return CLI::Validator(
        [min, max, range](std::string& text) -> std::string {
            long long v = 0;
            const char* end = text.data() + text.size();
            const auto [ptr, ec] = std::from_chars(text.data(), end, v);
            if (ec != std::errc() || ptr != end || v < min || v > max) return "must be an integer in " + range + ", got " + text;
            return {};
        },
        range);
}

CLI::Validator number_in(double min, double max) {
    const std::string range = "[" + number_text(min) + ", " + number_text(max) + "]";
    return CLI::Validator(
        [min, max, range](std::string& text) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v) || v < min || v > max)
                return "must be a number in " + range + ", got " + text;
            return {};
        },
        range);
}

CLI::Validator one_of(std::vector<std::string> choices) {
    std::string list;
    for (const std::string& c : choices) list += (list.empty() ? "" : ", ") + c;
    return CLI::Validator(
        [choices, list](std::string& text) -> std::string {
            for (const std::string& c : choices)
                if (c == text) return {};
            return "must be one of " + list + ", got \"" + text + "\"";
        },
        "{" + list + "}");
}

CLI::Validator not_empty() {
    return CLI::Validator([](std::string& text) -> std::string { return text.empty() ? "must not be empty" : ""; }, "");
}

int run_command_line(CLI::App& app, int argc, const char* const* argv) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help
        std::string command = "drape";
        const std::vector<CLI::App*> chosen = app.get_subcommands();
        for (const CLI::App* sub : chosen) command += " " + sub->get_name();
        std::fprintf(stderr, "%s: %s\n", command.c_str(), one_line(e, app, chosen.empty()).c_str());
        return exit_bad_input;
    }
    return command_exit_code();
}

}  // namespace drape
