// Skin cover system: see skin_cover_system.hpp.
#include "drape/systems/skin_cover_system.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <span>
#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/skin_cover.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/systems/cloth/body.hpp"
#include "drape/systems/cloth/collision.hpp"

namespace drape {
namespace {

// The garment's ellipsoids that may hold covered skin (holds_covered_skin, thin ones too),
// as the passes below use them: the frame's index (a bit of the masks, up to 64), whether it
// is thick enough to be chosen first, and the unit-sphere radius skin is drawn on in it.
struct Holder {
    std::uint32_t e = 0;
    bool thick = false;
    Real drawn = 1;
};

// Scratch of the passes below, kept between frames.
struct CoverScratch {
    std::vector<Holder> holders;        ///< The ellipsoids that may hold covered skin (list_holders).
    std::vector<std::uint64_t> inside;  ///< Per vertex: the bit of a holder that holds it (pull_in).
    std::vector<std::uint8_t> pull;     ///< Per vertex: it goes further in this round (pull_faces_in).
};

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
    cover.faces.clear();
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
    std::vector<bool> covered(mesh.vertex_count(), false);
    for (const std::uint32_t v : cover.vertices) covered[v] = true;
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
        if (covered[mesh.indices[t]] && covered[mesh.indices[t + 1]] && covered[mesh.indices[t + 2]])
            cover.faces.push_back(static_cast<std::uint32_t>(t));
}

void list_holders(std::span<const EllipsoidFrame> frames, std::vector<Holder>& holders) {
    holders.clear();
    for (std::size_t e = 0; e < frames.size() && e < 64; ++e)
        if (holds_covered_skin(frames[e], true))
            holders.push_back({static_cast<std::uint32_t>(e), holds_covered_skin(frames[e]), skin_cover_depth(frames[e])});
}

// The holder that holds `x` deepest (the thin ones only when no thick one holds it); none
// (nullptr) when `x` is in none.
const Holder* deepest_holding(std::span<const EllipsoidFrame> frames, std::span<const Holder> holders, const Vec3& x) {
    const Holder* deepest = nullptr;
    Real best = 1;
    for (const bool thin_too : {false, true}) {
        for (const Holder& h : holders) {
            if (!thin_too && !h.thick) continue;
            const Real y = to_unit_sphere(frames[h.e], x).norm();
            if (y < best) {
                best = y;
                deepest = &h;
            }
        }
        if (deepest) break;
    }
    return deepest;
}

// Pulls the covered vertices of `skin` that stand out of the holders, or lie less deep in
// them than a pulled vertex is drawn (skin_cover_system.hpp): onto the nearest along its
// centre line, skin_cover_depth inside it; the thin ones only where no thick one is within
// reach. `held`: per vertex, the bit of the holder it ends in (0: none).
std::uint64_t pull_in(std::span<const EllipsoidFrame> frames, std::span<const Holder> holders, const SkinCover& cover,
                      SkinnedMesh& skin, std::vector<std::uint64_t>& held) {
    // Where skin at x goes: `deep` already deep enough in one; else `to` the nearest along
    // its centre line, `scale` what takes x to its drawn depth, `nearest` how far outside it
    // x lies.
    struct Pull {
        bool deep = false;
        const Holder* to = nullptr;  // the deep one when deep
        Real nearest = std::numeric_limits<Real>::infinity();
        Real scale = 1;
    };
    const auto pull_for = [&](const Vec3& x, bool thin_too) {
        Pull p;
        for (const Holder& h : holders) {
            if (!thin_too && !h.thick) continue;
            const EllipsoidFrame& f = frames[h.e];
            const Vec3 d = x - f.center;
            const Real y = (f.to_unit * d).norm();
            if (y <= h.drawn) {  // already as deep as a pulled vertex is drawn
                p.deep = true;
                p.to = &h;
                return p;
            }
            const Real outside = d.norm() * (1 - 1 / y);  // along the centre line to the surface (< 0 inside)
            if (outside < p.nearest) {
                p.nearest = outside;
                p.to = &h;
                p.scale = h.drawn / y;
            }
        }
        return p;
    };
    const auto within_reach = [](const Pull& p) { return p.deep || (p.to != nullptr && p.nearest <= skin_cover_reach_m); };
    std::uint64_t pulled = 0;
    held.assign(skin.positions.cols(), 0);
    for (const std::uint32_t v : cover.vertices) {
        const Eigen::Index vi = static_cast<Eigen::Index>(v);
        const Vec3 x = skin.positions.col(vi);
        Pull p = pull_for(x, false);
        if (!within_reach(p)) p = pull_for(x, true);  // the thin ones only where no other is near
        if (!within_reach(p)) continue;
        held[v] = std::uint64_t(1) << p.to->e;
        if (p.deep) continue;
        const EllipsoidFrame& f = frames[p.to->e];
        skin.positions.col(vi) = f.center + (x - f.center) * p.scale;
        ++pulled;
    }
    return pulled;
}

// Faces drawn as flat triangles between covered vertices can stand out where the vertices
// do not: a face 10-15 cm across (a low-polygon body) bridges the crease between two
// ellipsoids that the cloth follows in. While a face's centre or an edge's middle lies
// outside every holder, its three vertices go as much further toward the centre of the
// holder each lies deepest in as they are drawn in it, at most face_rounds times. A face
// whose three vertices lie in one holder lies in it whole (an ellipsoid is convex) and is
// not looked at: `inside`, per vertex, the bit of a holder that holds it (pull_in's).
// A vertex held by a thin piece only goes toward that piece's centre: skin there lies under
// the cloth, and with thick holders only, Female_Alternative's skirt in the sanitizer
// build, whose fit leaves her right hip to a piece 1 cm thin, drew 65 of 9,932 tested
// points outside the garment instead of 56. Returns the pulls.
std::uint64_t pull_faces_in(std::span<const EllipsoidFrame> frames, std::span<const Holder> holders, const MeshAsset& mesh,
                            const SkinCover& cover, SkinnedMesh& skin, CoverScratch& scratch) {
    constexpr int face_rounds = 4;
    std::vector<std::uint64_t>& inside = scratch.inside;
    std::vector<std::uint8_t>& pull = scratch.pull;
    pull.assign(mesh.vertex_count(), 0);
    // Whether x lies outside every holder, those of `near` (the face's vertices') tried first.
    const auto outside = [&](const Vec3& x, std::uint64_t near) {
        for (std::uint64_t bits = near; bits != 0; bits &= bits - 1)
            if (to_unit_sphere(frames[static_cast<std::size_t>(std::countr_zero(bits))], x).norm() <= 1) return false;
        for (const Holder& h : holders)
            if ((near >> h.e & 1) == 0 && to_unit_sphere(frames[h.e], x).norm() <= 1) return false;
        return true;
    };
    std::uint64_t pulled = 0;
    for (int round = 0; round < face_rounds; ++round) {
        bool any = false;
        for (const std::uint32_t t : cover.faces) {
            const std::uint32_t i[3] = {mesh.indices[t], mesh.indices[t + 1], mesh.indices[t + 2]};
            if ((inside[i[0]] & inside[i[1]] & inside[i[2]]) != 0) continue;
            const std::uint64_t near = inside[i[0]] | inside[i[1]] | inside[i[2]];
            const Vec3 a = skin.positions.col(i[0]), b = skin.positions.col(i[1]), c = skin.positions.col(i[2]);
            if (!outside((a + b + c) / 3, near) && !outside((a + b) / 2, near) && !outside((b + c) / 2, near) &&
                !outside((a + c) / 2, near))
                continue;
            for (const std::uint32_t v : i) pull[v] = 1;
            any = true;
        }
        if (!any) break;
        for (const std::uint32_t v : cover.vertices) {
            if (!pull[v]) continue;
            pull[v] = 0;
            const Eigen::Index vi = static_cast<Eigen::Index>(v);
            const Vec3 x = skin.positions.col(vi);
            const Holder* to = deepest_holding(frames, holders, x);
            if (to == nullptr) continue;  // beyond the cover's reach: left where it is
            const EllipsoidFrame& f = frames[to->e];
            skin.positions.col(vi) = f.center + (x - f.center) * to->drawn;
            inside[v] = std::uint64_t(1) << to->e;
            ++pulled;
        }
    }
    return pulled;
}

void cover_all(Registry& registry, std::vector<EllipsoidFrame>& frames, CoverScratch& scratch) {
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
        list_holders(frames, scratch.holders);
        cover->pulled += pull_in(frames, scratch.holders, *cover, *skin, scratch.inside);
        cover->pulled_for_faces += pull_faces_in(frames, scratch.holders, *skin->mesh, *cover, *skin, scratch);
    });
}

}  // namespace

Real skin_cover_depth(const EllipsoidFrame& f) noexcept {
    // A point at unit-sphere radius y lies at least (1 - y) r_min inside: the map to the
    // unit sphere stretches no distance by more than 1 / r_min.
    return std::max(Real(0.5), 1 - std::max(skin_cover_inset, skin_cover_min_depth_m / f.radii_m.minCoeff()));
}

bool holds_covered_skin(const EllipsoidFrame& f, bool thin_too) noexcept {
    return f.active && f.give_m <= 0 && (thin_too || f.radii_m.minCoeff() >= skin_cover_min_radius_m);
}

void cover_skin(Registry& registry) {
    std::vector<EllipsoidFrame> frames;
    CoverScratch scratch;
    cover_all(registry, frames, scratch);
}

System make_skin_cover_system() {
    System s;
    s.name = "skin_cover";
    s.phase = Phase::render;
    s.reads = components<Garment, EllipsoidCollider, Skeleton>();
    s.writes = components<SkinnedMesh>();  // and the SkinCover it adds to each garment (not a gate)
    s.run = [frames = std::vector<EllipsoidFrame>{}, scratch = CoverScratch{}](Registry& registry, const FrameContext&) mutable {
        cover_all(registry, frames, scratch);
    };
    return s;
}

}  // namespace drape
