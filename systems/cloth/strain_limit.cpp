// Provot strain limiting (method §4.1, §4.2); step order in strain_limit.hpp.
#include "systems/cloth/strain_limit.hpp"

#include <algorithm>
#include <cmath>

namespace drape {
namespace {

// Removes the component of `d` along particle i's plane normal (if it has a plane).
inline Vec3 in_plane(const Matrix3X* plane, std::uint32_t i, const Vec3& d) {
    if (plane == nullptr) return d;
    const Vec3 p = plane->col(i);
    return d - p.dot(d) * p;
}

inline void move(Matrix3X& x, Matrix3X& v, std::uint32_t i, const Vec3& dx, Real inv_h) {
    x.col(i) += dx;
    v.col(i) += dx * inv_h;
}

}  // namespace

void limit_strain(const SpringPhase& springs, Matrix3X& x, Matrix3X& v, std::span<const std::uint8_t> movable,
                  const StrainLimitOptions& o) {
    const std::size_t n = springs.size();
    const std::uint32_t* a = springs.a.data();
    const std::uint32_t* b = springs.b.data();
    const Real* rest = springs.rest_m.data();
    const Real stretch = 1 + o.limit;
    const Real inv_h = o.h_s > 0 ? 1 / o.h_s : 0;
    const Matrix3X* plane = o.plane_normal;

    for (int it = 0; it < o.iterations; ++it) {
        for (std::size_t s = 0; s < n; ++s) {
            const bool ma = movable[a[s]] != 0, mb = movable[b[s]] != 0;
            if (!ma && !mb) continue;
            const Vec3 d = x.col(b[s]) - x.col(a[s]);
            const Real length_sq = d.squaredNorm();
            const Real max_length = stretch * rest[s];
            if (length_sq <= max_length * max_length) continue;
            const Real length = std::sqrt(length_sq);
            const Vec3 excess = d * ((length - max_length) / length);  // from a toward b
            if (ma && mb) {
                move(x, v, a[s], in_plane(plane, a[s], Real(0.5) * excess), inv_h);
                move(x, v, b[s], in_plane(plane, b[s], Real(-0.5) * excess), inv_h);
            } else if (ma) {
                move(x, v, a[s], in_plane(plane, a[s], excess), inv_h);
            } else {
                move(x, v, b[s], in_plane(plane, b[s], -excess), inv_h);
            }
        }
    }
    if (!o.ordered_pass) return;

    for (std::size_t s = 0; s < n; ++s) {
        const std::uint32_t fixed_end = movable[b[s]] ? a[s] : b[s];
        const std::uint32_t moving = movable[b[s]] ? b[s] : a[s];
        if (!movable[moving]) continue;
        const Vec3 d = x.col(moving) - x.col(fixed_end);
        const Real max_length = stretch * rest[s];
        if (d.squaredNorm() <= max_length * max_length) continue;
        Vec3 target;
        const bool has_plane = plane != nullptr && plane->col(moving).squaredNorm() > 0;
        if (!has_plane) {
            target = x.col(fixed_end) + d * (max_length / d.norm());
        } else {
            // Keep the particle on its plane: rescale the in-plane part of d so |d| = max.
            const Vec3 p = plane->col(moving);
            const Vec3 d_normal = p.dot(d) * p;
            const Vec3 d_plane = d - d_normal;
            const Real room = max_length * max_length - d_normal.squaredNorm();
            const Real in_plane_length = d_plane.norm();
            const Real scale = room > 0 && in_plane_length > 0 ? std::sqrt(room) / in_plane_length : Real(0);
            target = x.col(fixed_end) + d_normal + scale * d_plane;
        }
        move(x, v, moving, target - x.col(moving), inv_h);
    }
}

Real max_strain(const SpringPhase& springs, const Matrix3X& x) {
    Real worst_sq = 0;
    for (std::size_t s = 0; s < springs.size(); ++s) {
        const Real ratio_sq = (x.col(springs.b[s]) - x.col(springs.a[s])).squaredNorm() /
                              (springs.rest_m[s] * springs.rest_m[s]);
        worst_sq = std::max(worst_sq, ratio_sq);
    }
    return worst_sq > 1 ? std::sqrt(worst_sq) - 1 : Real(0);
}

}  // namespace drape

