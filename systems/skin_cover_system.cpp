// Skin cover system: see skin_cover_system.hpp.
#include "systems/skin_cover_system.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "components/ellipsoid_collider.hpp"
#include "components/garment.hpp"
#include "components/skeleton.hpp"
#include "components/skin_cover.hpp"
#include "components/skinned_mesh.hpp"
#include "systems/cloth/body.hpp"

namespace drape {
namespace {

// Per bone of the character: true for the bones of an arm, a hand or the head (from its
// colliders' regions) and every bone below them.
std::vector<bool> free_limb_bones(Registry& registry, Entity character, const SkeletonAsset& skeleton) {
    std::vector<bool> limb(skeleton.size(), false);
    registry.view<EllipsoidCollider>().each([&](Entity, EllipsoidCollider& c) {
        if (c.character == character && hangs_outside_garments(c.region) && c.bone >= 0 && static_cast<std::size_t>(c.bone) < limb.size())
            limb[static_cast<std::size_t>(c.bone)] = true;
    });
    for (std::size_t b = 0; b < limb.size(); ++b) {  // parents come first
        const int parent = skeleton.parents[b];
        if (parent >= 0 && static_cast<std::size_t>(parent) < b && limb[static_cast<std::size_t>(parent)]) limb[b] = true;
    }
    return limb;
}

// The covered vertices of `skin` under `g` (skin_cover_system.hpp, "Covered"); `frames`: the
// garment's colliders now (update_frames).
void choose_cover(Registry& registry, const Garment& g, std::span<const EllipsoidFrame> frames, const SkinnedMesh& skin,
                  const Skeleton& skeleton, SkinCover& cover) {
    cover.vertices.clear();
    cover.chosen_for = g.fabric;
    const MeshAsset& mesh = *skin.mesh;
    cover.mesh_vertices = mesh.vertex_count();
    if (g.state.x.cols() == 0 || skin.positions.cols() != static_cast<Eigen::Index>(mesh.vertex_count())) return;
    // The rest shape where the garment hangs now: its lowest point and its highest pin.
    const Affine3 anchor = anchor_frame(frames, g.body.anchor);
    Real low = std::numeric_limits<Real>::infinity(), high = -low;
    const bool rest = g.body.rest_local.cols() == g.state.x.cols();
    for (Eigen::Index p = 0; p < g.state.x.cols(); ++p) {
        const Real y = rest ? (anchor * Vec3(g.body.rest_local.col(p))).y() : g.state.x(1, p);
        low = std::min(low, y);
    }
    for (const PinBinding& pin : g.state.pins) high = std::max(high, g.state.x(1, static_cast<Eigen::Index>(pin.particle)));
    if (g.state.pins.empty()) high = g.state.x.row(1).maxCoeff();
    const std::vector<bool> limb = free_limb_bones(registry, g.body.character, *skeleton.asset);
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const Eigen::Index vi = static_cast<Eigen::Index>(v);
        Eigen::Index strongest = 0;
        mesh.bone_weights.col(vi).maxCoeff(&strongest);
        const int bone = mesh.bone_indices(strongest, vi);
        if (bone < 0 || static_cast<std::size_t>(bone) >= limb.size() || limb[static_cast<std::size_t>(bone)]) continue;
        const Real y = skin.positions(1, vi);
        if (y >= low && y <= high) cover.vertices.push_back(static_cast<std::uint32_t>(v));
    }
}

// Pulls the covered vertices of `skin` that stand out of `frames`, or lie less deep in them
// than a pulled vertex is drawn (skin_cover_system.hpp).
std::uint64_t pull_in(std::span<const EllipsoidFrame> frames, const SkinCover& cover, SkinnedMesh& skin) {
    std::uint64_t pulled = 0;
    for (const std::uint32_t v : cover.vertices) {
        const Eigen::Index vi = static_cast<Eigen::Index>(v);
        const Vec3 x = skin.positions.col(vi);
        Real nearest = std::numeric_limits<Real>::infinity();
        const EllipsoidFrame* to = nullptr;
        Real scale = 1;
        bool inside = false;
        for (const EllipsoidFrame& f : frames) {
            if (!f.active || f.give_m > 0) continue;  // cloth may lie inside one that gives
            const Vec3 d = x - f.center;
            const Real y = (f.to_unit * d).norm();
            if (y <= 1 - skin_cover_inset) {  // already as deep as a pulled vertex is drawn
                inside = true;
                break;
            }
            const Real outside = d.norm() * (1 - 1 / y);  // along the centre line to the surface (< 0 inside)
            if (outside < nearest) {
                nearest = outside;
                to = &f;
                scale = (1 - skin_cover_inset) / y;
            }
        }
        if (inside || to == nullptr || !(nearest <= skin_cover_reach_m)) continue;
        skin.positions.col(vi) = to->center + (x - to->center) * scale;
        ++pulled;
    }
    return pulled;
}

void cover_all(Registry& registry, std::vector<EllipsoidFrame>& frames) {
    registry.view<Garment>().each([&](Entity e, Garment& g) {
        auto* skin = registry.try_get<SkinnedMesh>(g.body.character);
        const auto* skeleton = registry.try_get<Skeleton>(g.body.character);
        if (!skin || !skin->mesh || !skeleton || !skeleton->asset ||
            skin->positions.cols() != static_cast<Eigen::Index>(skin->mesh->vertex_count()))
            return;
        SkinCover* cover = registry.try_get<SkinCover>(e);
        if (cover == nullptr) cover = &registry.emplace<SkinCover>(e);
        update_frames(registry, g.body, frames, 1);
        if (cover->chosen_for != g.fabric || cover->mesh_vertices != skin->mesh->vertex_count())
            choose_cover(registry, g, frames, *skin, *skeleton, *cover);
        cover->pulled += pull_in(frames, *cover, *skin);
    });
}

}  // namespace

void cover_skin(Registry& registry) {
    std::vector<EllipsoidFrame> frames;
    cover_all(registry, frames);
}

System make_skin_cover_system() {
    System s;
    s.name = "skin_cover";
    s.phase = Phase::render;
    s.reads = components<Garment, EllipsoidCollider, Skeleton>();
    s.writes = components<SkinnedMesh>();  // and the SkinCover it adds to each garment (not a gate)
    s.run = [frames = std::vector<EllipsoidFrame>{}](Registry& registry, const FrameContext&) mutable { cover_all(registry, frames); };
    return s;
}

}  // namespace drape
