#include "systems/cloth_constraint_system.hpp"

#include <memory>

#include "components/ellipsoid_collider.hpp"
#include "components/garment.hpp"
#include "components/skeleton.hpp"
#include "components/transform.hpp"
#include "systems/cloth/garment_step.hpp"
#include "systems/cloth/parallel.hpp"

namespace drape {

System make_cloth_constraint_system() {
    auto batch = std::make_shared<GarmentBatch>();
    return System{"cloth_constraint", Phase::simulation, {}, components<Garment>(),
                  components<EllipsoidCollider, Skeleton, Transform>(),
                  [batch](Registry& registry, const FrameContext& context) {
                      for_each_garment(registry, *batch, [&](Garment& g) { constrain_garment(g, context); });
                  }};
}

}  // namespace drape
