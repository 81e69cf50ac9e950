// What every `drape` subcommand shares: its exit status, its one-line errors, value checks
// whose messages read like Drape's other errors, and the parsing of the command line.
//
// Exit codes of every subcommand: 0 done; 1 bad input (a command-line value, a scene or
// character file, a name that does not exist, an output that would overwrite a file) or a
// run that failed (one line on stderr says which); `--help` exits 0.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

namespace drape {

/// Exit code of the subcommand that ran (set by its callback).
int& command_exit_code();

/// Exit code for bad input and failed runs, the same for every subcommand.
inline constexpr int exit_bad_input = 1;

/// Reports an error of subcommand `command` as one line on stderr ("drape play: --size:
/// must be WxH ...") and makes exit_bad_input its exit code, which it returns.
int command_error(std::string_view command, const std::string& message);

/// Command-line checks whose messages read like Drape's other errors; CLI11 puts the
/// option in front: "--frames: must be an integer in [1, 10000000], got -3". Non-numbers,
/// NaN and infinities are refused with the same line.
[[nodiscard]] CLI::Validator integer_in(long long min, long long max);
[[nodiscard]] CLI::Validator number_in(double min, double max);
/// One of `choices`: "--garment: must be one of skirt, dress, none, got \"hat\"".
[[nodiscard]] CLI::Validator one_of(std::vector<std::string> choices);
/// A file name, folder or clip that is not empty ("--scene \"$SCENE\"" with SCENE unset).
[[nodiscard]] CLI::Validator not_empty();

/// Parses and runs the command line. A command-line error is one line on stderr
/// ("drape play: --frames: must be ...") and returns exit_bad_input; help returns 0.
[[nodiscard]] int run_command_line(CLI::App& app, int argc, const char* const* argv);

}  // namespace drape
