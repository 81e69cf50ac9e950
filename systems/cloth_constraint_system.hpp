// Cloth constraints (method §4): Provot strain limiting on the warp (§4.1); for the
// simplified model layer-2 placement in its planes and Provot on the weft (§4.2). Second of
// the three cloth systems in each substep.
#pragma once

#include "engine/core/scheduler.hpp"

namespace drape {

/// Phase simulation; writes Garment; reads EllipsoidCollider, Skeleton, Transform when present.
[[nodiscard]] System make_cloth_constraint_system();

}  // namespace drape
