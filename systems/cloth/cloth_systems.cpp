#include "systems/cloth/cloth_systems.hpp"

#include "systems/cloth_collision_system.hpp"
#include "systems/cloth_constraint_system.hpp"
#include "systems/cloth_integration_system.hpp"

namespace drape {

void add_cloth_systems(Scheduler& scheduler, const ClothSolverSettings& settings) {
    scheduler.add(make_cloth_integration_system());
    scheduler.add(make_cloth_constraint_system());
    scheduler.add(make_cloth_collision_system());
    scheduler.set_substep_rule([settings](Registry& registry, double fixed_dt_s) {
        return cloth_substeps(registry, fixed_dt_s, settings);
    });
}

}  // namespace drape
