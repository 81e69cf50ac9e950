// Cloth collision (method §5): candidate lists, last-collided first, unit-sphere test,
// centre-line response; then the non-finite check (report, count, reset). Third of the
// three cloth systems in each substep.
#pragma once

#include "engine/core/scheduler.hpp"

namespace drape {

/// Phase simulation; writes Garment; reads EllipsoidCollider, Skeleton, Transform when present.
[[nodiscard]] System make_cloth_collision_system();

}  // namespace drape
