// Cloth constraint system; see cloth_constraint_system.hpp.
#include "systems/cloth_constraint_system.hpp"

namespace drape {

void run_cloth_constraint(const GarmentBatch& batch, const ClothSubstep& substep) {
    batch.for_each([&](Garment& g, GarmentSolver& s) {
        constrain_garment(g, s, substep);
        if (substep.last()) record_strain(g);
    });
}

}  // namespace drape
