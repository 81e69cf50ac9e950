// The artist's mesh carried by a garment's particles: see garment_surface.hpp.
#include "drape/systems/cloth/garment_surface.hpp"

#include <algorithm>
#include <array>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "drape/engine/core/mesh_normals.hpp"
#include "drape/systems/character/skin_surface.hpp"

namespace drape {
namespace {

// The normal at a vertex carried by particles a, b, c with weights w: their vertex normals
// `n` so weighted, normalised (zero where they cancel).
Vec3 carried_normal(const Matrix3X& n, const std::array<std::uint32_t, 3>& carriers, const Vec3& w) {
    const Vec3 sum = w[0] * n.col(carriers[0]) + w[1] * n.col(carriers[1]) + w[2] * n.col(carriers[2]);
    const Real length = sum.norm();
    return length > 0 ? Vec3(sum / length) : Vec3::Zero();
}

}  // namespace

GarmentSurface embed_surface(const GarmentMeshAsset& mesh, const GridGarment& grid, const Fabric& fabric) {
    GarmentSurface s;
    s.triangles = mesh.indices;
    s.uvs = mesh.uvs;
    if (!mesh.base_color.empty() && mesh.uvs.cols() == mesh.positions.cols()) s.base_color = std::make_shared<const Image>(mesh.base_color);
    // The grid where it was cut, in particle order, with its vertex normals from the
    // garment's own triangles (as place_surface takes them from where the particles are).
    Matrix3X rest(3, static_cast<Eigen::Index>(fabric.particle_count()));
    for (std::size_t k = 0; k < fabric.grid.size(); ++k) rest.col(fabric.grid[k]) = grid.grid_positions.col(static_cast<Eigen::Index>(k));
    Matrix3X rest_normals;
    vertex_normals(rest, fabric.triangles, rest_normals);
    const SkinSurface cut(rest, rest_normals, fabric.triangles);
    const Eigen::Index vertices = mesh.positions.cols();
    s.carriers.resize(static_cast<std::size_t>(vertices));
    s.weights.resize(3, vertices);
    s.offset_m.resize(vertices);
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, vertices), [&](const tbb::blocked_range<Eigen::Index>& r) {
        for (Eigen::Index v = r.begin(); v < r.end(); ++v) {
            const Eigen::Vector3d p = mesh.positions.col(v).cast<double>();
            const SkinSurface::Closest c = cut.closest(p);
            std::array<std::uint32_t, 3> carriers{0, 0, 0};
            Vec3 weights(1, 0, 0);
            if (c.triangle >= 0) {
                carriers = cut.triangle(static_cast<std::size_t>(c.triangle));
                weights = c.weights.cast<Real>();
            }
            s.carriers[static_cast<std::size_t>(v)] = carriers;
            s.weights.col(v) = weights;
            s.offset_m[v] = static_cast<Real>((p - c.point).dot(carried_normal(rest_normals, carriers, weights).cast<double>()));
        }
    });
    return s;
}

void place_surface(GarmentSurface& s, const Matrix3X& x, std::span<const std::uint32_t> triangles) {
    const auto vertices = static_cast<Eigen::Index>(s.carriers.size());
    s.positions.resize(3, vertices);
    s.normals.resize(3, vertices);
    vertex_normals(x, triangles, s.particle_normals);
    for (Eigen::Index v = 0; v < vertices; ++v) {
        const auto& [a, b, c] = s.carriers[static_cast<std::size_t>(v)];
        if (std::max({a, b, c}) >= x.cols()) {  // not this garment's particles: nothing to draw
            s.positions.resize(3, 0);
            return;
        }
        const Vec3 w = s.weights.col(v);
        const Vec3 normal = carried_normal(s.particle_normals, s.carriers[static_cast<std::size_t>(v)], w);
        s.positions.col(v) = w[0] * x.col(a) + w[1] * x.col(b) + w[2] * x.col(c) + s.offset_m[v] * normal;
        s.normals.col(v) = normal;
    }
}

}  // namespace drape
