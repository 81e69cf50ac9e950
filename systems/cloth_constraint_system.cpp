// Cloth constraint system; see cloth_constraint_system.hpp.
#include "drape/systems/cloth_constraint_system.hpp"

namespace drape {

void run_cloth_constraint_round(const GarmentBatch& batch, const ClothSubstep& substep, int round) {
    batch.for_each([&](Garment& g, GarmentSolver& s) {
        if (round < constraint_rounds(g)) constrain_round(g, s, substep, round);
    });
}

void run_cloth_constraint_finish(const GarmentBatch& batch, const ClothSubstep& substep) {
    batch.for_each([&](Garment& g, GarmentSolver& s) { finish_constraints(g, s, substep); });
}

}  // namespace drape
