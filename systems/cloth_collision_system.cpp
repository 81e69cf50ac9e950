// Cloth collision system; see cloth_collision_system.hpp.
#include "systems/cloth_collision_system.hpp"

namespace drape {

void run_cloth_collision(const Registry& registry, const GarmentBatch& batch, const ClothSubstep& substep) {
    batch.for_each([&](Garment& g, GarmentSolver& s) { collide_garment_step(registry, g, s, substep); });
}

}  // namespace drape
