// What a character holds, for people (`drape inspect`) and for tools (`--json`).
#pragma once

#include <string>

#include "drape/engine/assets/character_asset.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/ellipsoid_fit.hpp"

namespace drape {

/// The body's ellipsoids' coverage and bulge on the character's rest pose.
[[nodiscard]] CoverageReport rest_pose_coverage(const CharacterAsset& character, const CharacterBody& body,
                                                double tolerance_m = 0.01);

/// Human-readable report: meshes, vertices, bones, clips with durations, the body's
/// ellipsoids, coverage and height in metres.
[[nodiscard]] std::string character_report_text(const CharacterAsset& character, const CharacterBody& body,
                                                const CoverageReport& coverage);

/// The same as JSON (one object; keys documented in the text report's order).
[[nodiscard]] std::string character_report_json(const CharacterAsset& character, const CharacterBody& body,
                                                const CoverageReport& coverage);

}  // namespace drape
