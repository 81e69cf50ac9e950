#include "systems/cloth_integration_system.hpp"

#include <memory>

#include "components/ellipsoid_collider.hpp"
#include "components/garment.hpp"
#include "components/skeleton.hpp"
#include "components/transform.hpp"
#include "systems/cloth/garment_step.hpp"
#include "systems/cloth/parallel.hpp"

namespace drape {

System make_cloth_integration_system() {
    auto batch = std::make_shared<GarmentBatch>();
    return System{"cloth_integration", Phase::simulation, {}, components<Garment>(),
                  components<EllipsoidCollider, Skeleton, Transform>(),
                  [batch](Registry& registry, const FrameContext& context) {
                      for_each_garment(registry, *batch, [&](Garment& g) { integrate_garment(registry, g, context); });
                  }};
}

}  // namespace drape
