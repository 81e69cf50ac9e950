// The garment surface system (phase render, after the skinning and the skin cover, before
// the render system): every garment drawn as authored (components/garment_surface.hpp) has
// its artist's mesh put on where its particles are now (systems/cloth/garment_surface.hpp),
// once per drawn frame. Reads Garment; writes GarmentSurface. Only a world that draws adds
// it (game/world.cpp), and it runs only while a garment has a surface: the built-in garments
// are drawn as their grids.
#pragma once

#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"

namespace drape {

[[nodiscard]] System make_garment_surface_system();

/// Places every garment's surface: the system's run, for callers without a scheduler.
void place_garment_surfaces(Registry& registry);

}  // namespace drape
