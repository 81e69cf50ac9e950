// One character's animation update: see animation.hpp.
#include "drape/systems/character/animation.hpp"

#include <cmath>

#include "drape/components/animation_player.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/systems/character/pose.hpp"

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
        sample_clip(*player.clip, asset, player.time_s, player.in_place, skeleton.local, player.loop);  // a one-key clip is a pose
    } else {
        rest_pose(asset, skeleton.local);
    }
    compose_pose(asset, skeleton.local, skeleton.global);
    skinning_matrices(asset, skeleton.global, skeleton.skinning);
}

}  // namespace drape
