// A garment: a cooked, shared topology (the "fabric") and light per-instance particle
// state in structure-of-arrays form (method §3, §4, §5).
//
// The cloth systems own the meaning of most fields; the render system reads only
// `x`, `topology->triangles` and `color`.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "engine/core/math.hpp"
#include "engine/core/registry.hpp"

namespace drape {

/// Which mass-spring model integrates the garment (method §3.1).
enum class ClothModel : std::uint8_t {
    simplified,  ///< The paper's: stretch springs, warp layer integrated, weft placed (§3.2).
    classic,     ///< Provot's: stretch, shear and bend springs, every particle integrated.
};

/// How particles find the ellipsoids they touch (method §5).
enum class CollisionMode : std::uint8_t {
    candidate_lists,  ///< Per-particle candidate lists + last-collided first.
    brute_force,      ///< Every particle against every ellipsoid.
};

/// Immutable garment data shared by every instance.
struct GarmentTopology {
    std::vector<std::uint32_t> triangles;   ///< Render triangles over the particle grid.
};

struct Garment {
    std::shared_ptr<const GarmentTopology> topology;
    Entity body;                             ///< The character the garment is worn by.
    ClothModel model = ClothModel::simplified;
    CollisionMode collision = CollisionMode::candidate_lists;
    Vec3 color = Vec3(0.75f, 0.12f, 0.18f);  ///< Linear RGB.

    Matrix3X x;         ///< Particle positions, world, m.
    Matrix3X v;         ///< Particle velocities, m/s.
    VectorX inv_mass;   ///< 1/kg; 0 = pinned.
};

}  // namespace drape
