// Plays an animation clip on a character's skeleton (method §1.1).
#pragma once

#include <memory>

#include "drape/engine/assets/animation_clip.hpp"

namespace drape {

/// Per-instance playback state.
struct AnimationPlayer {
    std::shared_ptr<const AnimationClip> clip;
    double time_s = 0;
    double speed = 1;           ///< Playback rate multiplier.
    bool loop = true;
    bool in_place = true;       ///< true: the root's horizontal travel is removed; false: it moves the Transform (root motion).
    bool playing = true;
    int cycles = 0;             ///< Completed loops (root motion advances the Transform once per loop).
};

}  // namespace drape
