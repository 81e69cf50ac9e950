// A floor that garments collide with: the horizontal plane y = height_m, world up +Y (the
// floor the renderer draws lies at y = 0). One entity with this component puts a floor
// under every garment of the registry; with several, the highest counts.
#pragma once

#include "drape/engine/core/math.hpp"

namespace drape {

struct GroundPlane {
    Real height_m = 0;  ///< World y of the floor, m.
};

}  // namespace drape
