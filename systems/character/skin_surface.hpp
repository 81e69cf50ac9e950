// A posed skin as a triangle surface: closest points and inside/outside, and evenly spread
// sample points. Ellipsoid fitting samples the skin with it, the coverage report measures
// how far ellipsoid surfaces stand out of the skin with it (method §2), and the body
// landmarks cut the skin into horizontal sections with it.
//
// Closest-point queries run on a bounding-volume hierarchy of the triangles (median split
// of the longest axis, a few triangles per leaf). "Outside" is judged at the closest point
// by the normal interpolated from its triangle's vertex normals: a point lies outside
// when it is on the side that normal points to. That needs no closed mesh, so it works on
// characters built from separate pieces (a shirt over a body, rigid robot parts).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "drape/engine/core/math.hpp"

namespace drape {

/// A triangle surface with closest-point queries. Positions and normals in one space
/// (model space at a pose); degenerate triangles are kept out of the queries.
class SkinSurface {
public:
    /// `indices`: triangles, three per face, into the columns of `positions` and `normals`.
    SkinSurface(const Matrix3X& positions, const Matrix3X& normals, std::span<const std::uint32_t> indices);

    /// The closest point of the surface to a query point.
    struct Closest {
        Eigen::Vector3d point = Eigen::Vector3d::Zero();   ///< On the surface.
        Eigen::Vector3d normal = Eigen::Vector3d::UnitY(); ///< Interpolated vertex normal there (unit).
        double distance_m = 0;                             ///< From the query point.
        std::int64_t triangle = -1;                        ///< Index of the face; -1: the surface is empty.
        Eigen::Vector3d weights = Eigen::Vector3d::UnitX(); ///< `point`'s barycentric weights on triangle(triangle)'s vertices.
        bool outside = false;                              ///< The query point is on the normal's side.
    };
    [[nodiscard]] Closest closest(const Eigen::Vector3d& point) const;

    /// The first face a ray meets: the smallest `t` > 1e-9 with `origin + t direction` on a
    /// face (Moller-Trumbore; of faces met at the same `t`, the lowest index).
    struct Hit {
        double t = 0;
        std::int64_t triangle = -1;  ///< -1: the ray meets no face.
    };
    [[nodiscard]] Hit first_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;

    [[nodiscard]] std::size_t triangle_count() const noexcept { return m_triangles.size(); }
    /// Total area of the faces, m^2.
    [[nodiscard]] double area_m2() const noexcept { return m_area_m2; }
    [[nodiscard]] const Eigen::Vector3d& vertex(std::uint32_t i) const noexcept { return m_positions[i]; }
    [[nodiscard]] const Eigen::Vector3d& vertex_normal(std::uint32_t i) const noexcept { return m_normals[i]; }
    /// Vertex indices of usable (non-degenerate) face `t`.
    [[nodiscard]] const std::array<std::uint32_t, 3>& triangle(std::size_t t) const noexcept { return m_triangles[t]; }

private:
    struct Node {
        Eigen::AlignedBox3d box;
        std::uint32_t first = 0;  // leaf: first triangle in m_order; inner: index of the left child
        std::uint32_t count = 0;  // leaf: number of triangles; inner: 0
    };
    std::uint32_t build(std::uint32_t first, std::uint32_t count, std::vector<Eigen::Vector3d>& centroids);

    std::vector<Eigen::Vector3d> m_positions, m_normals;
    std::vector<std::array<std::uint32_t, 3>> m_triangles;
    std::vector<std::uint32_t> m_order;  // triangles in leaf order
    std::vector<Node> m_nodes;
    double m_area_m2 = 0;
};

/// A point on the skin for fitting: where, which way out, and whose it is.
struct SkinSample {
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  ///< Unit, outward.
    std::uint32_t vertex = 0;                            ///< The nearest corner's vertex (its bone weights).
    bool is_vertex = false;                              ///< A mesh vertex itself, not a point inside a face.
};

/// Every vertex, plus points inside each face more than twice `spacing_m` long (one per
/// spacing^2 of its area, spread evenly), so that a coarse mesh is sampled about as densely
/// as a fine one. Deterministic: faces in order.
[[nodiscard]] std::vector<SkinSample> sample_skin(const Matrix3X& positions, const Matrix3X& normals,
                                                  std::span<const std::uint32_t> indices, double spacing_m);

}  // namespace drape
