// Cloth integration system; see cloth_integration_system.hpp.
#include "drape/systems/cloth_integration_system.hpp"

namespace drape {

void run_cloth_integration(const Registry& registry, const GarmentBatch& batch, const ClothSubstep& substep) {
    batch.for_each([&](Garment& g, GarmentSolver& s) {
        if (substep.index == 0) begin_garment_step(registry, g, s, substep.count);
        integrate_garment(registry, g, s, substep);
    });
}

}  // namespace drape
