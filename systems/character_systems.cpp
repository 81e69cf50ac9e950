#include "drape/systems/character_systems.hpp"

#include "drape/systems/animation_system.hpp"
#include "drape/systems/collider_system.hpp"

namespace drape {

void add_character_systems(Scheduler& scheduler) {
    scheduler.add(make_animation_system());
    scheduler.add(make_collider_system());
}

}  // namespace drape
