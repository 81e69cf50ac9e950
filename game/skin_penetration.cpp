// Cloth behind the skin; see skin_penetration.hpp.
#include "drape/game/skin_penetration.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>
#include <utility>

#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/components/transform.hpp"
#include "drape/engine/assets/skinning.hpp"
#include "drape/systems/character/skin_surface.hpp"

namespace drape {
namespace {

// A file's mesh splits its vertices where its shading is flat or its UVs have seams, and
// each copy carries its own face's normal: at a convex corner a point outside then lies
// behind the plane of the face whose copy it happens to be nearest. The side is judged
// instead on the welded surface (copies at one place made one vertex, within 0.01 mm) by
// angle-weighted vertex normals, which tell inside from outside at corners and edges too
// (Baerentzen and Aanaes, 2005). `triangles` is rewritten to the welded vertices. The side
// of a piece wound inside out is taken from its signed volume (skin_depths).
std::pair<Matrix3X, Matrix3X> weld(const Matrix3X& positions, std::vector<std::uint32_t>& triangles) {
    std::unordered_map<std::uint64_t, std::uint32_t> at;
    std::vector<std::uint32_t> to_welded(static_cast<std::size_t>(positions.cols()));
    std::vector<Eigen::Index> first;
    constexpr double grid = 1e-5;
    for (Eigen::Index v = 0; v < positions.cols(); ++v) {
        std::uint64_t key = 0;
        for (int i = 0; i < 3; ++i)
            key = key * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(std::llround(double(positions(i, v)) / grid));
        const auto [it, added] = at.try_emplace(key, static_cast<std::uint32_t>(first.size()));
        if (added) first.push_back(v);
        to_welded[static_cast<std::size_t>(v)] = it->second;
    }
    Matrix3X welded(3, static_cast<Eigen::Index>(first.size()));
    for (std::size_t w = 0; w < first.size(); ++w) welded.col(static_cast<Eigen::Index>(w)) = positions.col(first[w]);
    Matrix3X normals = Matrix3X::Zero(3, welded.cols());
    for (std::size_t f = 0; f + 2 < triangles.size(); f += 3) {
        std::array<std::uint32_t, 3> t{};
        for (int i = 0; i < 3; ++i) t[i] = triangles[f + i] = to_welded[triangles[f + i]];
        const Vec3 a = welded.col(t[0]), b = welded.col(t[1]), c = welded.col(t[2]);
        const Vec3 face = (b - a).cross(c - a);
        if (!(face.norm() > 0)) continue;
        const Vec3 n = face.normalized();
        const std::array<Vec3, 3> p{a, b, c};
        for (int i = 0; i < 3; ++i) {
            const Vec3 e1 = p[(i + 1) % 3] - p[i], e2 = p[(i + 2) % 3] - p[i];
            const Real angle = std::acos(std::clamp(e1.normalized().dot(e2.normalized()), Real(-1), Real(1)));
            if (std::isfinite(angle)) normals.col(t[i]) += angle * n;
        }
    }
    for (Eigen::Index v = 0; v < normals.cols(); ++v) {
        const Real length = normals.col(v).norm();
        normals.col(v) = length > 0 ? Vec3(normals.col(v) / length) : Vec3::UnitY();
    }
    return {std::move(welded), std::move(normals)};
}

// Whether the ray from `o` along `d` first meets the surface from inside, through a face
// that looks along it (it leaves the body there).
bool leaves_through_surface(const SkinSurface& surface, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
    const SkinSurface::Hit hit = surface.first_hit(o, d);
    if (hit.triangle < 0) return false;
    const auto& t = surface.triangle(static_cast<std::size_t>(hit.triangle));
    const Eigen::Vector3d& a = surface.vertex(t[0]);
    return (surface.vertex(t[1]) - a).cross(surface.vertex(t[2]) - a).dot(d) > 0;
}

}  // namespace

SkinDepths skin_depths(const Registry& registry, const Garment& garment) {
    SkinDepths out;
    const Entity character = garment.body.character;
    const auto* skin = registry.try_get<SkinnedMesh>(character);
    const auto* skeleton = registry.try_get<Skeleton>(character);
    const auto* transform = registry.try_get<Transform>(character);
    if (skin == nullptr || !skin->mesh || skeleton == nullptr || transform == nullptr || skeleton->skinning.empty()) return out;
    const MeshAsset& mesh = *skin->mesh;
    Matrix3X positions, normals;
    skin_mesh(mesh, skeleton->skinning, transform->matrix(), positions, normals);
    std::vector<std::uint32_t> drawn;
    drawn.reserve(mesh.indices.size());
    for (std::size_t s = 0; s < mesh.submeshes.size(); ++s) {
        if (s < skin->hidden.size() && skin->hidden[s] != 0) continue;
        const Submesh& part = mesh.submeshes[s];
        const std::size_t begin = drawn.size();
        drawn.insert(drawn.end(), mesh.indices.begin() + part.first_index, mesh.indices.begin() + part.first_index + part.index_count);
        // A piece wound inside out (its faces turned in: negative signed volume) is turned
        // round, so that its normals point out of it as the side test needs.
        // (Measured about the piece's own middle: an open piece, a sleeve or a trouser leg,
        // has no volume of its own, and about the origin its sign would be arbitrary.)
        Vec3 middle = Vec3::Zero();
        for (std::size_t i = begin; i < drawn.size(); ++i) middle += positions.col(drawn[i]);
        if (drawn.size() > begin) middle /= Real(drawn.size() - begin);
        double volume = 0;
        for (std::size_t f = begin; f + 2 < drawn.size(); f += 3) {
            const Vec3 a = positions.col(drawn[f]) - middle, b = positions.col(drawn[f + 1]) - middle, c = positions.col(drawn[f + 2]) - middle;
            volume += double(a.dot(b.cross(c)));
        }
        if (volume < 0)
            for (std::size_t f = begin; f + 2 < drawn.size(); f += 3) std::swap(drawn[f + 1], drawn[f + 2]);
    }
    if (mesh.submeshes.empty()) drawn = mesh.indices;
    const auto [welded, welded_normals] = weld(positions, drawn);
    const SkinSurface surface(welded, welded_normals, drawn);
    if (surface.triangle_count() == 0) return out;
    out.measured = true;
    const Matrix3X& x = garment.state.x;
    for (Eigen::Index p = 0; p < x.cols(); ++p) {
        if (!x.col(p).allFinite()) continue;
        if (garment.state.inv_mass[p] == 0) {
            const SkinSurface::Closest c = surface.closest(x.col(p).cast<double>());
            const bool behind = c.triangle >= 0 && !c.outside && leaves_through_surface(surface, x.col(p).cast<double>(), -c.normal);
            out.pins_m.push_back(behind ? -c.distance_m : c.distance_m);
            continue;
        }
        ++out.free;
        const SkinSurface::Closest c = surface.closest(x.col(p).cast<double>());
        // Behind its closest point, and a second opinion: deeper in, the other way from
        // that point, the body must be left through its surface. A piece that is an open
        // shell or turned in at a rim (Male_Casual's shoes: 28 faces) fools the first test
        // alone, by tens of centimetres.
        if (c.triangle >= 0 && !c.outside &&
            leaves_through_surface(surface, x.col(p).cast<double>(), -c.normal)) {
            out.behind_m.push_back(c.distance_m);
            out.behind_particles.push_back(static_cast<std::uint32_t>(p));
        }
    }
    return out;
}

}  // namespace drape
