// Animation system: see animation_system.hpp.
#include "drape/systems/animation_system.hpp"

#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "drape/components/animation_player.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/systems/character/animation.hpp"

namespace drape {

System make_animation_system() {
    System s;
    s.name = "animation";
    s.phase = Phase::animation;
    s.reads = {};
    s.writes = components<AnimationPlayer, Skeleton>();
    s.optional_reads = components<Transform>();
    // Characters are independent (each task writes one player, skeleton and transform), so
    // they are posed in parallel; the result does not depend on the thread count.
    s.run = [entities = std::vector<Entity>{}](Registry& registry, const FrameContext& context) mutable {
        entities.clear();
        registry.view<AnimationPlayer, Skeleton>().each([&](Entity e, AnimationPlayer&, Skeleton&) { entities.push_back(e); });
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, entities.size()), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i < r.end(); ++i) {
                const Entity e = entities[i];
                advance_animation(registry.get<AnimationPlayer>(e), registry.get<Skeleton>(e), registry.try_get<Transform>(e),
                                  context.fixed_dt_s);
            }
        });
    };
    return s;
}

}  // namespace drape
