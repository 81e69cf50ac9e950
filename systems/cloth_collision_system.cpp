// Cloth collision system; see cloth_collision_system.hpp.
#include "drape/systems/cloth_collision_system.hpp"

namespace drape {

void run_cloth_collision_prepare(const Registry& registry, const GarmentBatch& batch, const ClothSubstep& substep) {
    batch.for_each([&](Garment& g, GarmentSolver& s) { prepare_collision(registry, g, s, substep); });
}

void run_cloth_collision_round(const Registry& registry, const GarmentBatch& batch, const ClothSubstep& substep, int round) {
    batch.for_each([&](Garment& g, GarmentSolver& s) {
        if (round < constraint_rounds(g)) collide_round(registry, g, s, substep, round);
    });
}

void run_cloth_collision_finish(const Registry& registry, const GarmentBatch& batch, const ClothSubstep& substep) {
    batch.for_each([&](Garment& g, GarmentSolver& s) { finish_collision(registry, g, s, substep); });
}

}  // namespace drape
