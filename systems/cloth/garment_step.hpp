// One garment through one substep, as the three cloth systems run it. Each function is the
// whole per-garment body of its system, callable without a scheduler (tests, benchmarks).
//
// Order within a substep (method §1 item 4):
//   integrate_garment   method §3.3-§3.4 (+ pins, §3.5)
//   constrain_garment   method §4.1 warp, §4.2 weft
//   collide_garment_step method §5, then the non-finite check
#pragma once

#include "components/garment.hpp"
#include "engine/core/registry.hpp"
#include "engine/core/scheduler.hpp"

namespace drape {

/// Sizes scratch arrays and masks after building or changing a garment (no-op when current).
void prepare_garment(Garment& garment);

/// Forces and symplectic Euler on the integrated particles (simplified: layer 1; classic:
/// all), then pins. At substep 0 also restarts the step's counters and pin targets.
void integrate_garment(const Registry& registry, Garment& garment, const FrameContext& context);

/// Provot on the warp; simplified: weft placement and Provot on the weft (§4.2); classic:
/// Provot on warp and weft. Records max strain at the last substep.
void constrain_garment(Garment& garment, const FrameContext& context);

/// Collision against the colliders at the end of the substep, then the non-finite check:
/// a garment with a NaN or infinity is reported on stderr, counted, and reset.
void collide_garment_step(const Registry& registry, Garment& garment, const FrameContext& context);

/// Back to rest around the body at its current place: the rest shape in the anchor's frame,
/// pins on their bindings, velocities those of the body, collision state cleared, pushed
/// out of the colliders.
void reset_garment_state(const Registry& registry, Garment& garment);

/// Count of non-finite coordinates in x and v.
[[nodiscard]] std::uint64_t count_non_finite(const Garment& garment);

}  // namespace drape
