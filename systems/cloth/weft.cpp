// Layer-2 placement (method §4.2); step order in weft.hpp.
#include "systems/cloth/weft.hpp"

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
                Matrix3X& v, Matrix3X& plane_normal, Real h) {
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
        Vec3 xi = x.col(i) + h * vi;
        xi -= p.dot(xi - x.col(a)) * p;
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
