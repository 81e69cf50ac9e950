// Animation system: see animation_system.hpp.
#include "systems/animation_system.hpp"

#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "components/animation_player.hpp"
#include "components/skeleton.hpp"
#include "components/transform.hpp"
#include "systems/character/pose.hpp"

namespace drape {

void advance_animation(AnimationPlayer& player, Skeleton& skeleton, Transform* transform, double dt_s) {
    if (!skeleton.asset) return;
    const SkeletonAsset& asset = *skeleton.asset;
    if (player.clip) {
        if (player.playing && std::isfinite(player.speed) && player.clip->duration_s > 0) {
            const ClipTime t = wrap_clip_time(player.time_s + dt_s * player.speed, player.clip->duration_s, player.loop);
            if (t.cycles != 0 && !player.in_place && transform != nullptr) {
                // The pose jumps back by one cycle's travel; the character moves forward by it.
                transform->position += transform->rotation * (transform->scale * Real(t.cycles) * player.clip->travel_m);
            }
            player.cycles += t.cycles;
            player.time_s = t.time_s;
        }
        sample_clip(*player.clip, asset, player.time_s, player.in_place, skeleton.local);  // a one-key clip is a pose
    } else {
        rest_pose(asset, skeleton.local);
    }
    compose_pose(asset, skeleton.local, skeleton.global);
    skinning_matrices(asset, skeleton.global, skeleton.skinning);
}

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
