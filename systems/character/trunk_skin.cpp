// The trunk's skin. See trunk_skin.hpp.
#include "drape/systems/character/trunk_skin.hpp"

#include <algorithm>

#include "drape/engine/assets/skinning.hpp"

namespace drape {

std::optional<TrunkSkin> trunk_skin(const MeshAsset& body, const SkeletonAsset& skeleton, const BodyLandmarks* landmarks,
                                    std::span<const Affine3> skinning, bool with_legs) {
    const std::size_t bones = skeleton.size();
    if (body.vertex_count() == 0 || body.indices.empty() || (!skinning.empty() && skinning.size() != bones)) return std::nullopt;
    std::vector<char> trunk(bones, 1);
    if (landmarks)
        for (const LimbChain* limb : {&landmarks->left_leg, &landmarks->right_leg, &landmarks->left_arm, &landmarks->right_arm}) {
            const bool leg = limb == &landmarks->left_leg || limb == &landmarks->right_leg;
            if (!(with_legs && leg) && limb->root >= 0 && static_cast<std::size_t>(limb->root) < bones)
                trunk[static_cast<std::size_t>(limb->root)] = 0;
        }
    for (std::size_t b = 0; b < bones; ++b)  // parents precede children
        if (skeleton.parents[b] >= 0 && !trunk[static_cast<std::size_t>(skeleton.parents[b])]) trunk[b] = 0;
    const auto trunk_share = [&](std::uint32_t v) {
        Real share = 0;
        for (int i = 0; i < 4; ++i) {
            const int bone = body.bone_indices(i, v);
            if (bone >= 0 && static_cast<std::size_t>(bone) < bones && trunk[static_cast<std::size_t>(bone)]) share += body.bone_weights(i, v);
        }
        return share;
    };
    std::vector<std::uint32_t> triangles;
    for (std::size_t t = 0; t + 2 < body.indices.size(); t += 3) {
        const std::uint32_t a = body.indices[t], b = body.indices[t + 1], c = body.indices[t + 2];
        if (std::max({a, b, c}) >= body.vertex_count()) continue;
        if (trunk_share(a) >= Real(0.5) && trunk_share(b) >= Real(0.5) && trunk_share(c) >= Real(0.5))
            triangles.insert(triangles.end(), {a, b, c});
    }
    if (triangles.empty()) return std::nullopt;
    if (skinning.empty()) return TrunkSkin{std::move(trunk), triangles, SkinSurface(body.bind_positions, body.bind_normals, triangles)};
    Matrix3X positions, normals;
    skin_mesh(body, skinning, Affine3::Identity(), positions, normals);
    return TrunkSkin{std::move(trunk), triangles, SkinSurface(positions, normals, triangles)};
}

std::vector<BoneInfluence> trunk_influences(const TrunkSkin& skin, const MeshAsset& body, const Eigen::Vector3d& point) {
    std::vector<BoneInfluence> out;
    const SkinSurface::Closest c = skin.surface.closest(point);
    if (c.triangle < 0) return out;
    const auto& t = skin.surface.triangle(static_cast<std::size_t>(c.triangle));
    double total = 0;
    for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 4; ++i) {
            const std::uint32_t vertex = t[static_cast<std::size_t>(k)];
            const int bone = body.bone_indices(i, vertex);
            const double w = c.weights[k] * double(body.bone_weights(i, vertex));
            if (w <= 0 || bone < 0 || static_cast<std::size_t>(bone) >= skin.trunk.size() || !skin.trunk[static_cast<std::size_t>(bone)]) continue;
            auto it = std::find_if(out.begin(), out.end(), [&](const BoneInfluence& b) { return b.bone == bone; });
            if (it == out.end()) out.push_back({bone, w});
            else it->weight += w;
            total += w;
        }
    if (total <= 0) return {};
    for (BoneInfluence& b : out) b.weight /= total;
    std::sort(out.begin(), out.end(), [](const BoneInfluence& a, const BoneInfluence& b) { return a.weight > b.weight || (a.weight == b.weight && a.bone < b.bone); });
    return out;
}

}  // namespace drape
