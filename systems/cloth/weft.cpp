// Layer-2 placement (method §4.2); step order in weft.hpp.
#include "systems/cloth/weft.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {
namespace {

// Unit normal of the plane of layer-2 particle k, or zero when degenerate.
inline Vec3 plane_of(const Fabric& t, const Matrix3X& normals, const Matrix3X& x, std::size_t k) {
    const std::uint32_t a = t.weft_left[k], b = t.weft_right[k];
    const Vec3 edge = x.col(b) - x.col(a);
    const Vec3 n = normals.col(a) + normals.col(b);
    const Vec3 p = edge.cross(n);
    const Real length = p.norm();
    return length > Real(1e-12) ? Vec3(p / length) : Vec3::Zero();
}

}  // namespace

void compute_layer1_normals(const Fabric& t, const Matrix3X& x, Matrix3X& normals) {
    const std::size_t n = t.normal_up.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 warp = x.col(t.normal_down[i]) - x.col(t.normal_up[i]);
        const Vec3 weft = x.col(t.normal_next[i]) - x.col(t.normal_prev[i]);
        const Vec3 c = warp.cross(weft);
        const Real length = c.norm();
        normals.col(static_cast<Eigen::Index>(i)) = length > Real(1e-12) ? Vec3(c / length) : Vec3::Zero();
    }
}

namespace {

// The frame of layer-2 entry k on its chord: chord point q, unit chord direction e, and u,
// the in-plane unit direction across the chord (toward the average normal); false when the
// chord or its plane is degenerate.
inline bool chord_frame(const Fabric& t, const Matrix3X& normals, const Matrix3X& x, std::size_t k, Vec3& q, Vec3& e,
                        Vec3& u, Vec3& p) {
    const std::uint32_t a = t.weft_left[k], b = t.weft_right[k];
    const Real s = t.weft_t[k];
    q = (1 - s) * x.col(a) + s * x.col(b);
    const Vec3 edge = x.col(b) - x.col(a);
    const Real length = edge.norm();
    p = plane_of(t, normals, x, k);
    if (length <= Real(1e-9) || p.squaredNorm() == 0) return false;
    e = edge / length;
    u = p.cross(e);
    return true;
}

}  // namespace

void place_weft(const Fabric& t, const Matrix3X& normals, const VectorX& inv_mass, const Matrix2X& offsets, Matrix3X& x,
                Matrix3X& plane_normal) {
    for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
        const std::uint32_t i = t.weft_particle[k];
        plane_normal.col(i).setZero();
        if (inv_mass[i] == 0) continue;  // pinned in the fitting zone
        Vec3 q, e, u, p;
        if (!chord_frame(t, normals, x, k, q, e, u, p)) continue;  // stays where it is
        const Eigen::Index kk = static_cast<Eigen::Index>(k);
        x.col(i) = q + offsets(0, kk) * e + offsets(1, kk) * u;
        plane_normal.col(i) = p;
    }
}

void record_weft_offsets(const Fabric& t, const Matrix3X& normals, const Matrix3X& x, Matrix2X& offsets) {
    offsets.resize(2, static_cast<Eigen::Index>(t.weft_particle.size()));
    for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
        const Eigen::Index kk = static_cast<Eigen::Index>(k);
        Vec3 q, e, u, p;
        if (!chord_frame(t, normals, x, k, q, e, u, p)) {
            offsets.col(kk).setZero();
            continue;
        }
        const Vec3 d = x.col(t.weft_particle[k]) - q;
        offsets(0, kk) = d.dot(e);
        offsets(1, kk) = d.dot(u);
    }
}

Real weft_plane_distance(const Fabric& t, const Matrix3X& normals, const Matrix3X& x, std::size_t k) {
    const Vec3 p = plane_of(t, normals, x, k);
    return p.dot(x.col(t.weft_particle[k]) - x.col(t.weft_left[k]));
}

}  // namespace drape
