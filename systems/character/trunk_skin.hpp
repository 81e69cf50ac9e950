// The skin the trunk carries: where a garment's held edge is bound to the body (pins,
// method §3.5) and how a garment modelled on the bind pose is put on the current pose.
//
// The trunk is every bone but the limbs: each leg's and arm's chain from its first bone
// off the trunk (BodyLandmarks) and whatever hangs from it; without landmarks every bone.
// The trunk's skin is the triangles whose three vertices hang from the trunk for at least
// half of their weights. A point is bound to its closest point on that skin: the
// influences of that triangle's vertices on the trunk's bones, weighted by the closest
// point's barycentric weights and renormalised. They vary continuously over the skin, so
// neighbouring points of a waistband move together. (Bound to their nearest vertices'
// weights, neighbouring pins of a waistband took different vertices' weights, and a run
// stretched a pinned row to 2-5 times its rest length: Goblin's, Alien's and Male_Casual's
// runs.)
#pragma once

#include <optional>
#include <vector>

#include "drape/components/body_landmarks.hpp"
#include "drape/engine/assets/mesh_asset.hpp"
#include "drape/engine/assets/skeleton_asset.hpp"
#include "drape/engine/core/math.hpp"
#include "drape/systems/character/skin_surface.hpp"

namespace drape {

/// One bone's share in how a point moves.
struct BoneInfluence {
    int bone = -1;
    double weight = 0;
};

/// The trunk's skin at one pose.
struct TrunkSkin {
    std::vector<char> trunk;              ///< Per bone: 1 on the trunk.
    std::vector<std::uint32_t> triangles; ///< The trunk's skin: three vertex indices per face.
    SkinSurface surface;                  ///< Those faces at the pose they were taken in (model space).
};

/// The trunk's skin of `body` at the pose `skinning` gives (Skeleton::skinning; empty: the
/// bind pose); nothing when no face hangs from the trunk or the sizes disagree. `with_legs`:
/// the legs count as trunk too (the skin a hanging garment's free cloth follows: the max
/// distance's spheres on the skin, docs/cloth.md), only the arms left out.
[[nodiscard]] std::optional<TrunkSkin> trunk_skin(const MeshAsset& body, const SkeletonAsset& skeleton,
                                                  const BodyLandmarks* landmarks, std::span<const Affine3> skinning,
                                                  bool with_legs = false);

/// The trunk's influences at the closest point of its skin to `point` (model space, the
/// skin's pose): strongest first, summing to 1; empty when none.
[[nodiscard]] std::vector<BoneInfluence> trunk_influences(const TrunkSkin& skin, const MeshAsset& body, const Eigen::Vector3d& point);

}  // namespace drape
