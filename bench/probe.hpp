// Read-only probes the benchmarks take of a running Drape world: per-system time from the
// frame profiler, and a garment's springs, pins and colliders in the plain form the Bullet
// peer and the error metrics use.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "bench/bullet_cloth.hpp"
#include "drape/components/garment.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"

namespace drape::bench {

/// Where the simulation phase's time goes, by the cloth system names. Integration counts
/// the integration system and the constraint system (the paper's "integrate" includes the
/// Provot constraints and the weft placement, method §4); collision counts the collision
/// system; garment work is the whole simulation phase (the cloth step with its substep rule).
struct ClothSystemTime {
    double integrate_ms = 0;
    double collide_ms = 0;
    double garment_ms = 0;
    double animation_ms = 0;   ///< Animation phase.
    double skinning_ms = 0;    ///< Skinning phase (skin and colliders).
    double frame_ms = 0;       ///< Whole frames.
};

/// Totals (not means) of the scheduler's systems so far, grouped as above.
[[nodiscard]] ClothSystemTime cloth_system_totals(const Scheduler& scheduler);

/// `later - earlier`, divided by `frames` (per-frame means of a window).
[[nodiscard]] ClothSystemTime per_frame(const ClothSystemTime& later, const ClothSystemTime& earlier, double frames);

/// The names in each group, for reports ("integrate = cloth_integration + cloth_constraints").
[[nodiscard]] std::string cloth_system_grouping(const Scheduler& scheduler);

/// Structural springs of a garment's full grid (warp of both layers and weft) with their rest
/// lengths: the springs both engines' strain is measured on.
struct StructuralSprings {
    std::vector<std::array<std::uint32_t, 2>> springs;
    std::vector<Real> rest_m;
};
[[nodiscard]] StructuralSprings structural_springs(const Fabric& topology);

/// Pinned particles (inv_mass == 0), in index order.
[[nodiscard]] std::vector<std::uint32_t> pinned_particles(const Garment& garment);

/// Unit sphere -> world of each collider the garment sees (skips missing entities).
[[nodiscard]] std::vector<Affine3> collider_worlds(const Registry& registry, const Garment& garment);

/// Every EllipsoidCollider's unit sphere -> world.
[[nodiscard]] std::vector<Affine3> all_collider_worlds(const Registry& registry);

}  // namespace drape::bench
