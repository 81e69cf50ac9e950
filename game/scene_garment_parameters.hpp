// Garment parameters as a scene names them: the cloth module's parameter table
// (systems/cloth/garment_parameters.hpp) plus one scene-level convenience, `particles`,
// a target particle count that chooses the grid. The scene file reader checks a garment's
// fields against these specs; tube_params() sets them on the builder's TubeParams through
// the table's member pointers; garment_parameters_markdown() is the list in docs/scenes.md.
#pragma once

#include <string>
#include <vector>

#include "drape/engine/core/error.hpp"
#include "drape/game/scene_description.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_parameters.hpp"

namespace drape {

/// `particles`: not a builder field but a target count; warp_lines and particles_per_line
/// are chosen with the garment type's default proportions (a scene gives either this or
/// those two). Its upper bound is max_garment_particles.
[[nodiscard]] const ParameterSpec& particles_parameter();

/// Every numeric field a scene's garment accepts: `particles`, then the table in order.
[[nodiscard]] std::vector<const ParameterSpec*> scene_garment_parameters();

/// The builder's parameters for a scene's garment: the type's defaults
/// (TubeParams::skirt() or dress()), each scene parameter set through its table row,
/// `particles` turned into a grid, then the colour, model and collision mode. The error
/// names a parameter that is in no table ("lenght_m: unknown garment parameter").
/// Ranges are not checked here: validate(TubeParams) does that when the garment is built.
[[nodiscard]] Result<TubeParams> tube_params(const GarmentDescription& garment);

/// The garment parameter table of docs/scenes.md, Markdown, one row per parameter:
/// name, range (with unit), skirt and dress defaults, whether a garment from a file takes
/// it, meaning. `drape scene-parameters` prints it; a test checks that docs/scenes.md holds
/// exactly this.
[[nodiscard]] std::string garment_parameters_markdown();

}  // namespace drape
