#include "systems/cloth_collision_system.hpp"

#include <memory>

#include "components/ellipsoid_collider.hpp"
#include "components/garment.hpp"
#include "components/skeleton.hpp"
#include "components/transform.hpp"
#include "systems/cloth/garment_step.hpp"
#include "systems/cloth/parallel.hpp"

namespace drape {

System make_cloth_collision_system() {
    auto batch = std::make_shared<GarmentBatch>();
    return System{"cloth_collision", Phase::simulation, {}, components<Garment>(),
                  components<EllipsoidCollider, Skeleton, Transform>(),
                  [batch](Registry& registry, const FrameContext& context) {
                      for_each_garment(registry, *batch, [&](Garment& g) { collide_garment_step(registry, g, context); });
                  }};
}

}  // namespace drape
