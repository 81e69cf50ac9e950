// Collider system: see collider_system.hpp.
#include "drape/systems/collider_system.hpp"

#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/systems/character/colliders.hpp"

namespace drape {

System make_collider_system() {
    System s;
    s.name = "colliders";
    s.phase = Phase::skinning;
    s.reads = components<Skeleton>();
    s.writes = components<EllipsoidCollider>();
    s.optional_reads = components<Transform>();
    // Colliders are independent (each task reads its character and writes one collider), so
    // they move in parallel; the result does not depend on the thread count.
    s.run = [colliders = std::vector<EllipsoidCollider*>{}](Registry& registry, const FrameContext& context) mutable {
        colliders.clear();
        registry.view<EllipsoidCollider>().each([&](Entity, EllipsoidCollider& c) { colliders.push_back(&c); });
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, colliders.size(), 16), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i < r.end(); ++i) {
                EllipsoidCollider& c = *colliders[i];
                const Skeleton* skeleton = registry.try_get<Skeleton>(c.character);
                if (skeleton == nullptr) continue;  // the character is gone
                update_collider(c, *skeleton, registry.try_get<Transform>(c.character), context.fixed_dt_s);
            }
        });
    };
    return s;
}

}  // namespace drape
