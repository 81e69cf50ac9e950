// Layer-2 placement (method §4.2); step order in weft.hpp.
#include "systems/cloth/weft.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {
namespace {

// Unit normal of the plane of layer-2 particle k, or zero when degenerate.
inline Vec3 plane_of(const GarmentTopology& t, const Matrix3X& normals, const Matrix3X& x, std::size_t k) {
    const std::uint32_t a = t.weft_left[k], b = t.weft_right[k];
    const Vec3 edge = x.col(b) - x.col(a);
    const Vec3 n = normals.col(a) + normals.col(b);
    const Vec3 p = edge.cross(n);
    const Real length = p.norm();
    return length > Real(1e-12) ? Vec3(p / length) : Vec3::Zero();
}

}  // namespace

void compute_layer1_normals(const GarmentTopology& t, const Matrix3X& x, Matrix3X& normals) {
    const std::size_t n = t.normal_up.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 warp = x.col(t.normal_down[i]) - x.col(t.normal_up[i]);
        const Vec3 weft = x.col(t.normal_next[i]) - x.col(t.normal_prev[i]);
        const Vec3 c = warp.cross(weft);
        const Real length = c.norm();
        normals.col(static_cast<Eigen::Index>(i)) = length > Real(1e-12) ? Vec3(c / length) : Vec3::Zero();
    }
}

void place_weft(const GarmentTopology& t, const Matrix3X& normals, const VectorX& inv_mass, Matrix3X& x,
                Matrix3X& v, Matrix3X& plane_normal, Real h, Real limit) {
    const Real stride = Real(t.weft_stride);
    for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
        const std::uint32_t i = t.weft_particle[k];
        if (inv_mass[i] == 0) {  // pinned in the fitting zone
            plane_normal.col(i).setZero();
            continue;
        }
        const std::uint32_t a = t.weft_left[k], b = t.weft_right[k];
        const Real s = t.weft_t[k];
        const Vec3 p = plane_of(t, normals, x, k);
        Vec3 vi = (1 - s) * v.col(a) + s * v.col(b);
        vi -= p.dot(vi) * p;
        const Vec3 edge = x.col(b) - x.col(a);
        const Real edge_length = edge.norm();
        const Vec3 q = (1 - s) * x.col(a) + s * x.col(b);
        Vec3 xi = q;
        if (edge_length > Real(1e-9) && p.squaredNorm() > 0) {
            const Vec3 u = p.cross(edge / edge_length);
            const Real l = (1 + limit) * t.weft_rest_m[k];
            const Real along = edge_length / stride;
            const Real beta = l > along ? std::sqrt(l * l - along * along) : Real(0);
            Real bulge = std::clamp((x.col(i) + h * vi - q).dot(u), -beta / 2, beta / 2);
            const std::uint32_t above = t.weft_above[k];
            if (above != std::numeric_limits<std::uint32_t>::max()) {
                // |q + b u - x_above| <= l_warp  <=>  (b + c)^2 <= l_warp^2 - |d|^2 + c^2.
                const Vec3 d = q - x.col(above);
                const Real c = d.dot(u);
                const Real l_warp = (1 + limit) * t.weft_above_rest_m[k];
                const Real room = l_warp * l_warp - d.squaredNorm() + c * c;
                const Real half = room > 0 ? std::sqrt(room) : Real(0);
                bulge = std::clamp(bulge, -c - half, -c + half);
            }
            xi += bulge * u;
        }
        v.col(i) = vi;
        x.col(i) = xi;
        plane_normal.col(i) = p;
    }
}

Real weft_plane_distance(const GarmentTopology& t, const Matrix3X& normals, const Matrix3X& x, std::size_t k) {
    const Vec3 p = plane_of(t, normals, x, k);
    return p.dot(x.col(t.weft_particle[k]) - x.col(t.weft_left[k]));
}

}  // namespace drape
