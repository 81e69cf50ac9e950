// Cloth integration (method §3.3-§3.4): the body-driven force of paper eq. 2 and symplectic
// Euler on the integrated particles (simplified model: layer 1; classic: all), then the
// fitting-zone pins (§3.5). First of the three cloth systems in each substep.
#pragma once

#include "engine/core/scheduler.hpp"

namespace drape {

/// Phase simulation; writes Garment; reads EllipsoidCollider, Skeleton, Transform when present.
[[nodiscard]] System make_cloth_integration_system();

}  // namespace drape
