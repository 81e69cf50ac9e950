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

void place_weft(const Fabric& t, const Matrix3X& normals, const VectorX& inv_mass, Matrix3X& x,
                Matrix3X& v, Matrix3X& plane_normal, Real h, Real limit) {
    constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    const Real stride = Real(t.weft_stride);
    const Real stretch = 1 + limit;
    const auto chord_point = [&](std::size_t k) {
        return Vec3((1 - t.weft_t[k]) * x.col(t.weft_left[k]) + t.weft_t[k] * x.col(t.weft_right[k]));
    };
    const auto within = [&](const Vec3& xi, std::uint32_t above, Real rest) {
        return (xi - x.col(above)).squaredNorm() <= stretch * stretch * rest * rest;
    };
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
        const Vec3 q = chord_point(k);
        Vec3 xi = q;
        if (edge_length > Real(1e-9) && p.squaredNorm() > 0) {
            const Vec3 u = p.cross(edge / edge_length);
            // Weft interval W = [-beta/2, beta/2] (step 3); it always holds 0.
            const Real l = stretch * t.weft_rest_m[k];
            const Real along = edge_length / stride;
            const Real half_beta = l > along ? std::sqrt(l * l - along * along) / 2 : Real(0);
            const Real wanted = std::clamp((x.col(i) + h * vi - q).dot(u), -half_beta, half_beta);
            Real bulge = wanted;
            const std::uint32_t above = t.weft_above[k];
            if (above != none) {
                // Warp interval I: |q + b u - x_above| <= l_warp  <=>  (b + c)^2 <= l_warp^2 - |d|^2 + c^2.
                const Real l_warp = stretch * t.weft_above_rest_m[k];
                // I within [-w, w]: false when empty.
                const auto warp_room = [&](Real& low, Real& high, Real w) {
                    const Vec3 d = q - x.col(above);
                    const Real c = d.dot(u);
                    const Real room = l_warp * l_warp - d.squaredNorm() + c * c;
                    if (room < 0) return false;
                    low = std::max(-w, -c - std::sqrt(room));
                    high = std::min(w, -c + std::sqrt(room));
                    return low <= high;
                };
                Real low = 0, high = 0;
                const bool hangs_from_pin = inv_mass[above] == 0;
                bool feasible = warp_room(low, high, half_beta);
                if (!feasible && !hangs_from_pin) {
                    // No bulge satisfies both: the particles above on this line go back onto
                    // their chords, from here upward until the spring above the topmost one
                    // holds. On chords, a warp spring is the blend of the two layer-1 warp
                    // springs beside it (at most 1.10 x rest), so 0 is then in I.
                    for (std::size_t j = k; j-- > 0 && t.weft_particle[j] == t.weft_above[j + 1];) {
                        const std::uint32_t pj = t.weft_particle[j], over = t.weft_above[j];
                        if (inv_mass[pj] == 0) break;
                        x.col(pj) = chord_point(j);
                        if (over == none || inv_mass[over] == 0 || within(x.col(pj), over, t.weft_above_rest_m[j])) break;
                    }
                    feasible = warp_room(low, high, half_beta);
                }
                if (!feasible) {
                    // Below a pinned row (whose skin points need not lie near this plane): the
                    // warp spring before the weft; if no bulge holds it, the nearest one.
                    // Elsewhere (only when the layer-1 warp beside it is over the limit, e.g.
                    // between pinned rows): the nearest one within W.
                    const Real c = (q - x.col(above)).dot(u);
                    if (!hangs_from_pin) low = high = std::clamp(-c, -half_beta, half_beta);
                    else if (!warp_room(low, high, std::numeric_limits<Real>::infinity())) low = high = -c;
                }
                bulge = std::clamp(wanted, low, high);
            }
            xi += bulge * u;
        }
        v.col(i) = vi;
        x.col(i) = xi;
        plane_normal.col(i) = p;
    }
}

bool lift_chords_below_pins(const Fabric& t, const VectorX& inv_mass, Matrix3X& x, Matrix3X& v,
                            Matrix3X& scratch, Real h, Real limit) {
    constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    constexpr int max_rounds = 32;
    // Targets a little inside the limits so that the rounds end with both sets of springs
    // strictly within them, float rounding included.
    constexpr Real aim = Real(0.995);
    const Real reach = 1 + limit;
    const Eigen::Index layer1 = static_cast<Eigen::Index>(t.layer1_count);
    const auto free_particle = [&](std::uint32_t i) { return inv_mass[i] != 0; };
    // The chords out of reach of the pinned particle above them.
    const auto out_of_reach = [&](Real scale) {
        for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
            const std::uint32_t above = t.weft_above[k];
            if (above == none || free_particle(above) || !free_particle(t.weft_particle[k])) continue;
            const Real s = t.weft_t[k];
            const Vec3 c = (1 - s) * x.col(t.weft_left[k]) + s * x.col(t.weft_right[k]);
            const Real l = scale * reach * t.weft_above_rest_m[k];
            if ((x.col(above) - c).squaredNorm() > l * l) return true;
        }
        return false;
    };
    if (!out_of_reach(1)) return false;

    // Alternating projections (Gauss-Seidel) onto two sets of constraints on layer 1:
    //   chord:  |(1 - s) x_a + s x_b - x_pinned| <= aim (1 + limit) rest   (layer-2 warp spring)
    //   warp:   |x_b - x_pinned| <= aim (1 + limit) rest                    (layer-1 warp spring,
    //                                                                         lifted ends only)
    // A chord's correction is the shortest move of its free ends that brings its point onto
    // the sphere (ends weighted by their share of the point); a layer-1 spring's moves its
    // free end. Both sets are convex, so the rounds converge wherever they meet.
    scratch.leftCols(layer1) = x.leftCols(layer1);
    const SpringPhase& warp = t.warp1;
    for (int round = 0; round < max_rounds && out_of_reach(1); ++round) {
        for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
            const std::uint32_t above = t.weft_above[k];
            if (above == none || free_particle(above) || !free_particle(t.weft_particle[k])) continue;
            const std::uint32_t a = t.weft_left[k], b = t.weft_right[k];
            const Real s = t.weft_t[k];
            const Real wa = free_particle(a) ? 1 - s : 0, wb = free_particle(b) ? s : 0;
            const Real share = wa * (1 - s) + wb * s;
            if (share <= 0) continue;  // both ends pinned: the skin decides
            const Vec3 to_pin = x.col(above) - ((1 - s) * x.col(a) + s * x.col(b));
            const Real distance = to_pin.norm(), l = aim * reach * t.weft_above_rest_m[k];
            if (distance <= l) continue;
            const Vec3 step = to_pin * ((distance - l) / (distance * share));
            x.col(a) += wa * step;
            x.col(b) += wb * step;
        }
        for (std::size_t s = 0; s < warp.size(); ++s) {
            const bool fa = free_particle(warp.a[s]), fb = free_particle(warp.b[s]);
            if (fa == fb) continue;  // only springs from a pinned particle to a free one
            const std::uint32_t pinned = fa ? warp.b[s] : warp.a[s], moving = fa ? warp.a[s] : warp.b[s];
            if (x.col(moving) == scratch.col(moving)) continue;  // not lifted: Provot's pass holds it
            const Vec3 d = x.col(moving) - x.col(pinned);
            const Real length = d.norm(), l = aim * reach * warp.rest_m[s];
            if (length > l) x.col(moving) = x.col(pinned) + d * (l / length);
        }
    }
    if (h > 0) v.leftCols(layer1) += (x.leftCols(layer1) - scratch.leftCols(layer1)) / h;
    return true;
}

Real weft_plane_distance(const Fabric& t, const Matrix3X& normals, const Matrix3X& x, std::size_t k) {
    const Vec3 p = plane_of(t, normals, x, k);
    return p.dot(x.col(t.weft_particle[k]) - x.col(t.weft_left[k]));
}

}  // namespace drape
