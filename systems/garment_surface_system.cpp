// Garment surface system: see garment_surface_system.hpp.
#include "drape/systems/garment_surface_system.hpp"

#include "drape/components/garment.hpp"
#include "drape/components/garment_surface.hpp"
#include "drape/systems/cloth/garment_surface.hpp"

namespace drape {

void place_garment_surfaces(Registry& registry) {
    registry.view<Garment, GarmentSurface>().each([](Entity, Garment& g, GarmentSurface& s) {
        if (g.fabric && g.state.x.cols() > 0) place_surface(s, g.state.x, g.fabric->triangles);
    });
}

System make_garment_surface_system() {
    System s;
    s.name = "garment_surface";
    s.phase = Phase::render;
    s.reads = components<Garment>();
    s.writes = components<GarmentSurface>();
    s.run = [](Registry& registry, const FrameContext&) { place_garment_surfaces(registry); };
    return s;
}

}  // namespace drape
