// How deep a garment's cloth lies behind its character's skin: the mesh a user sees, not
// the ellipsoids the cloth collides with (docs/cloth.md, "Quality after a frame").
//
// The skin is the character's mesh skinned at the skeleton's current pose, every submesh
// that is drawn (a modelled garment hidden under a simulated one is left out), before the
// skin cover system pulls covered skin in for drawing: that pull moves skin, not cloth, so
// it is a drawing aid and not measured. A free particle is behind the skin when it lies on
// the inner side of its closest point on the mesh (judged by the interpolated vertex
// normal there, systems/character/skin_surface.hpp); its depth is its distance to that
// point.
#pragma once

#include <cstdint>
#include <vector>

#include "drape/components/garment.hpp"
#include "drape/engine/core/registry.hpp"

namespace drape {

/// One garment after one frame.
struct SkinDepths {
    std::vector<double> behind_m;  ///< Depth of each free particle behind the skin, m.
    std::vector<std::uint32_t> behind_particles;  ///< Which particle each of behind_m is (its column in GarmentState::x).
    std::uint64_t free = 0;        ///< Free particles measured.
    std::vector<double> pins_m;    ///< Each pinned particle's distance from the skin, m: > 0 outside, < 0 behind it.
    bool measured = false;         ///< False: the character has no skinned mesh or skeleton.
};

/// Measures `garment` against its character's skin now.
[[nodiscard]] SkinDepths skin_depths(const Registry& registry, const Garment& garment);

}  // namespace drape
