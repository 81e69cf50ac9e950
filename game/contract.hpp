// The quality contract a garment is held to after every whole frame, and the verdict
// `drape play` prints on it, one line per garment:
//
//   skirt: strain p99 5.1 %, max 9.2 %, penetration 0.0 mm: within the contract
//   dress: strain p99 6.0 %, max 31.4 %, penetration 0.4 mm: outside the contract: strain max 31.4 % > 20 %
//
// The figures are a run's statistics (game/stats.hpp): the worst seen after any frame,
// and the 99th percentile of the strain over every spring of every frame.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "drape/game/scene_description.hpp"
#include "drape/game/stats.hpp"

namespace drape {

/// The limits of the contract (docs/cloth.md, "Quality after a frame").
struct QualityContract {
    double strain_p99 = 0.10;                 ///< 99th percentile of the structural-spring strain.
    double strain_max = 0.20;                 ///< Largest structural-spring strain.
    double penetration_after_frame_m = 0.002; ///< Deepest free particle inside the body, or below the floor, after a frame.
    double rise_above_pins_m = 0.15;          ///< Highest free particle above the highest pin.
    double compression_min = 0.25;            ///< Shortest structural spring over its rest length.
};

/// What a run broke, one phrase each ("strain max 31.4 % > 20 %", "3 non-finite values");
/// empty when the garment kept the contract. A NaN figure counts as broken.
[[nodiscard]] std::vector<std::string> contract_breaches(const GarmentStats& stats, const QualityContract& contract = {});

/// The verdict line of one garment, without a newline (see the top of this file).
[[nodiscard]] std::string garment_verdict(std::string_view name, const GarmentStats& stats,
                                          const QualityContract& contract = {});

/// The garments' names in a verdict, in scene order: the garment type ("skirt"); when the
/// scene has several garments, with its index and its character's file ("garments[1]
/// skirt on Male_Casual").
[[nodiscard]] std::vector<std::string> garment_names(const SceneDescription& scene);

}  // namespace drape
