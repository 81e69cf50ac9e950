// SkinSurface's ray query (systems/character/skin_surface.hpp): the hierarchy finds the face
// that testing every face finds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "drape/systems/character/skin_surface.hpp"

namespace drape {
namespace {

using Eigen::Vector3d;

// Where the ray meets face f (Moller-Trumbore), or infinity.
double meets(const SkinSurface& s, std::size_t f, const Vector3d& o, const Vector3d& d) {
    constexpr double never = std::numeric_limits<double>::infinity();
    const auto& t = s.triangle(f);
    const Vector3d &a = s.vertex(t[0]), &b = s.vertex(t[1]), &c = s.vertex(t[2]);
    const Vector3d e1 = b - a, e2 = c - a, q = d.cross(e2);
    const double det = e1.dot(q);
    if (std::abs(det) < 1e-14) return never;
    const Vector3d w = o - a;
    const double u = w.dot(q) / det;
    if (u < 0 || u > 1) return never;
    const Vector3d r = w.cross(e1);
    const double v = d.dot(r) / det;
    if (v < 0 || u + v > 1) return never;
    const double t_hit = e2.dot(r) / det;
    return t_hit > 1e-9 ? t_hit : never;
}

// A bumpy closed sphere of 40 x 20 quads, and inside it a second, smaller one: rays from
// inside and outside, at random and at faces, and along the axes.
TEST(SkinSurface, TheRayQueryFindsTheFaceEveryFaceTestedFinds) {
    std::mt19937 random(7);
    std::uniform_real_distribution<double> unit(-1, 1);
    std::vector<Vector3d> points;
    std::vector<std::uint32_t> indices;
    constexpr int around = 40, up = 20;
    for (const double radius : {0.3, 0.12}) {
        const auto first = static_cast<std::uint32_t>(points.size());
        for (int j = 0; j <= up; ++j)
            for (int i = 0; i < around; ++i) {
                const double polar = M_PI * j / up, azimuth = 2 * M_PI * i / around;
                const double r = radius * (1 + 0.1 * unit(random));
                points.emplace_back(r * std::sin(polar) * std::cos(azimuth), r * std::cos(polar), r * std::sin(polar) * std::sin(azimuth));
            }
        const auto at = [&](int i, int j) { return first + static_cast<std::uint32_t>(j * around + (i % around)); };
        for (int j = 0; j < up; ++j)
            for (int i = 0; i < around; ++i)
                for (const std::uint32_t v : {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)})
                    indices.push_back(v);
    }
    Matrix3X positions(3, static_cast<Eigen::Index>(points.size()));
    for (std::size_t v = 0; v < points.size(); ++v) positions.col(static_cast<Eigen::Index>(v)) = points[v].cast<Real>();
    const Matrix3X normals = positions.colwise().normalized();
    const SkinSurface surface(positions, normals, indices);
    ASSERT_GT(surface.triangle_count(), 3000u);
    int hits = 0, rays = 0;
    // Every face tested: the nearest one.
    const auto check = [&](const Vector3d& o, const Vector3d& d) {
        double nearest = std::numeric_limits<double>::infinity();
        for (std::size_t f = 0; f < surface.triangle_count(); ++f) nearest = std::min(nearest, meets(surface, f, o, d));
        const SkinSurface::Hit got = surface.first_hit(o, d);
        ++rays;
        if (std::isinf(nearest)) {
            EXPECT_EQ(got.triangle, -1) << "ray " << rays;
            return;
        }
        ++hits;
        ASSERT_GE(got.triangle, 0) << "ray " << rays << " from " << o.transpose() << " along " << d.transpose();
        EXPECT_NEAR(got.t, nearest, 1e-12) << "ray " << rays;
        EXPECT_NEAR(meets(surface, static_cast<std::size_t>(got.triangle), o, d), nearest, 1e-12) << "ray " << rays;
    };
    for (int k = 0; k < 2000; ++k) {
        const Vector3d o = 0.5 * Vector3d(unit(random), unit(random), unit(random));
        check(o, Vector3d(unit(random), unit(random), unit(random)).normalized());
        // At a face's middle, from outside or inside (a ray through a vertex or an edge
        // meets its faces or slips between them by rounding, each way of computing alike).
        const auto& f = surface.triangle(static_cast<std::size_t>(random() % surface.triangle_count()));
        const Vector3d middle = (surface.vertex(f[0]) + surface.vertex(f[1]) + surface.vertex(f[2])) / 3;
        check(o, (middle - o).normalized());
    }
    for (const Vector3d& d : {Vector3d(1, 0, 0), Vector3d(0, 1, 0), Vector3d(0, 0, 1), Vector3d(0, -1, 0)})
        check(Vector3d(0.01, 0.02, 0.03), d);
    check(Vector3d(2, 2, 2), Vector3d::UnitX());  // misses
    EXPECT_GT(hits, rays / 2);
    EXPECT_LT(hits, rays);
}

}  // namespace
}  // namespace drape
