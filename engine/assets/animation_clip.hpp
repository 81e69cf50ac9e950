// An animation clip as imported: key frames per bone, in seconds (method §1.1).
// Shared, immutable data; the per-instance playback state is components/animation_player.hpp.
#pragma once

#include <string>
#include <vector>

#include "drape/engine/core/math.hpp"

namespace drape {

/// Key frames of one bone. Times in seconds, ascending.
struct BoneChannel {
    int bone = -1;
    std::vector<float> position_times_s;
    std::vector<Vec3> positions;
    std::vector<float> rotation_times_s;
    std::vector<Quat> rotations;
    std::vector<float> scale_times_s;
    std::vector<Vec3> scales;
};

/// Immutable clip shared by every player.
struct AnimationClip {
    std::string name;
    double duration_s = 0;
    std::vector<BoneChannel> channels;
    /// The bone that carries the clip's travel (the shallowest bone with translation keys),
    /// -1 when none. Playing in place removes `travel_m` from it, spread linearly over the clip.
    int motion_bone = -1;
    Vec3 travel_m = Vec3::Zero();   ///< Horizontal model-space travel of `motion_bone` over one cycle.
    Vec3 travel_local = Vec3::Zero();  ///< The same in the motion bone's parent space.
    /// > 0: the clip nearly loops (its last pose is within a few degrees of its first but not
    /// on it, as exports of a cycle often are); played as a loop, its pose is blended into
    /// its first over this last stretch of the clip, so the seam does not jump. 0: none.
    double seam_blend_s = 0;
};

}  // namespace drape
