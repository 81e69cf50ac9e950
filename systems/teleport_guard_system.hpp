// The teleport guard (phase skinning, after the colliders; before the cloth): when a
// character's root moves further than a threshold within one fixed step (a game moving its
// Transform, a clip jumping), the jump is no motion the cloth should follow. Every garment
// the character wears is reset to its rest shape around the body at its new place
// (reset_garment, systems/cloth/garment_builder.hpp), and its colliders' velocities and
// accelerations are zeroed so that the jump does not reach the cloth through the body-driven
// force model (method §3.3).
//
// Reads Transform and Skeleton (the root is the first bone's global translation, through
// the character's Transform); writes Garment; reads EllipsoidCollider when there are any.
// The first step after the system is made only records where each root is.
#pragma once

#include <cstdint>
#include <memory>

#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"

namespace drape {

/// Counts of what the teleport guard did (shared with whoever made it).
struct TeleportLog {
    std::uint64_t teleports = 0;     ///< Jumps detected.
    std::uint64_t resets = 0;        ///< Garments reset because of them (or on request).
};

/// Forget the motion of a character's colliders: each one's previous pose becomes its pose
/// and its velocities and accelerations zero, so that a jump of the body (a teleport, a tool
/// putting the body back) reaches neither the body-driven force model nor a garment reset
/// after it (reset_garment gives the particles the anchor's velocity).
void forget_collider_motion(Registry& registry, Entity character);

/// The teleport guard: a root moving more than `threshold_m` within one fixed step counts as
/// a teleport in `log` and resets the garments the character wears.
[[nodiscard]] System make_teleport_guard_system(double threshold_m, std::shared_ptr<TeleportLog> log);

}  // namespace drape
