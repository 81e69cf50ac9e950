// Garments cut as a tailor would, for testing garments from files (docs/garments.md) and to
// start one's own from: each a mesh of flat pattern pieces (UVs in metres / 2 along the
// fabric: v down the grain, u across it) sewn round a character's body as it stands when
// the garment is put on, its held band painted red (COLOR_0). `drape make-garments` writes
// them; assets/garments/ holds those of the default avatar.
//
//   flared_skirt    four panels, each a flared piece (wider at the hem), sewn at the sides
//                   and the front and back centres; held at the waist.
//   wrap_skirt      one piece round the body from the front's left to its right, open at
//                   the front; held at the waist.
//   panel_dress     a front and a back panel sewn at the sides, from under the arms to below
//                   the knees; held at the chest.
//   cape            one piece round the back from shoulder to shoulder, hanging to the
//                   knees; held at the shoulders.
//
// Each panel is meshed finer than the cloth's grid (1.5 cm), so that the grid is resampled
// from the pattern, as a modelled garment's would be. Each fabric has a print in its colour
// (the mesh's base-colour texture, repeated every 2 m of fabric): the flared skirt a tartan,
// the wrap skirt stripes along the grain, the dress dots, the cape a twill.
#pragma once

#include <string>
#include <vector>

#include "drape/engine/assets/garment_file.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/game/scene_description.hpp"

namespace drape {

/// One cut garment.
struct CutGarment {
    std::string name;        ///< File stem: "flared_skirt", ...
    GarmentMeshAsset mesh;   ///< In the character's model space.
    int panels = 0;          ///< Pattern pieces.
    bool closed = false;     ///< Sewn all round the body.
    Vec3 color;              ///< Suggested linear RGB.
};

/// The four garments above, cut for the first character of `scene` (its clip's first pose),
/// measured from the built-in skirt's waistband and dress's chest band and the character's
/// shoulders.
[[nodiscard]] Result<std::vector<CutGarment>> cut_garments(const SceneDescription& scene);

}  // namespace drape
