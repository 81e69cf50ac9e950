// Fitting-zone pins (method §3.5): particles fixed to the body that follow the skin exactly.
//
// A pin is evaluated once per fixed step (its target). Within the step's substeps a pinned
// particle moves linearly from the previous target to the new one and reaches the new
// target exactly at the last substep, with velocity (target - previous) / fixed_dt.
// Kinds (components/garment.hpp PinKind):
//   world     x = local
//   collider  x = collider.world * local            (unit-sphere coordinates)
//   skinned   x = T * sum_i w_i * skinning[bone_i] * local   (linear blend skinning, the
//             same as the body mesh: Skeleton::skinning maps bind model space to current
//             model space; T is the character's Transform)
#pragma once

#include "drape/components/garment.hpp"
#include "drape/systems/cloth/garment_solver.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/engine/core/math.hpp"
#include "drape/engine/core/registry.hpp"

namespace drape {

/// World position of a pin now, or an error naming what is missing (collider, skeleton, bone).
[[nodiscard]] Result<Vec3> evaluate_pin(const Registry& registry, const Garment& garment, const PinBinding& pin);

/// Sets every pin's target for the new fixed step (previous <- last target), and with
/// GarmentConfig::max_distance_on_skin the spheres' centres (GarmentSolver::sphere_target).
/// On the first step, or when `snap`, previous = target. A pin that cannot be evaluated keeps
/// its last target.
void update_pin_targets(const Registry& registry, const Garment& garment, GarmentSolver& solver, bool snap);

/// Moves the pinned particles to fraction (substep + 1) / substeps of the step.
void apply_pins(Garment& garment, const GarmentSolver& solver, int substep, int substeps, Real fixed_dt_s);

/// Model-space skinning matrix blended from up to four bones (linear blend skinning).
[[nodiscard]] Affine3 blend_skinning(const std::vector<Affine3>& skinning, const Vec4i& bones, const Vec4& weights);

}  // namespace drape
