// Subcommands of the `drape` command. Each lives in its own file and adds itself to the
// command line; main() runs the one the user chose. What they share (exit codes, errors,
// value checks) is in game/command_line.hpp, how they write files in game/output_files.hpp.
#pragma once

#include <CLI/CLI.hpp>

#include "drape/game/command_line.hpp"

namespace drape {

/// `drape play`: runs a scene (the sample scene by default) and prints the frame budget.
void add_play_command(CLI::App& app);

/// `drape inspect FILE`: what a character file holds.
void add_inspect_command(CLI::App& app);

/// `drape make-avatar [--out FILE]`: writes the default avatar (assets/avatar.glb).
void add_make_avatar_command(CLI::App& app);

/// `drape export-motion CHARACTER --out FILE.bvh`: a character's clip as a BVH motion.
void add_export_motion_command(CLI::App& app);

void add_export_garment_command(CLI::App& app);

void add_make_garments_command(CLI::App& app);

/// `drape bench NAME`: benchmarks and reports (bench/).
void add_bench_command(CLI::App& app);

/// `drape scene-parameters`: the garment parameters of scene files, as docs/scenes.md lists them.
void add_scene_parameters_command(CLI::App& app);

}  // namespace drape
