// Skin surface queries and samples. See skin_surface.hpp.
#include "drape/systems/character/skin_surface.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {
namespace {

using Eigen::Vector3d;

constexpr std::uint32_t leaf_size = 4;

// Closest point of triangle abc to p, as barycentric weights (Ericson, Real-Time Collision
// Detection, 5.1.5: by the Voronoi region of p).
Vector3d closest_barycentric(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
    const Vector3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
    const Vector3d bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double v = d1 / (d1 - d3);
        return {1 - v, v, 0};
    }
    const Vector3d cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double w = d2 / (d2 - d6);
        return {1 - w, 0, w};
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return {0, 1 - w, w};
    }
    const double denominator = 1 / (va + vb + vc);
    const double v = vb * denominator, w = vc * denominator;
    return {1 - v - w, v, w};
}

double box_distance_squared(const Eigen::AlignedBox3d& box, const Vector3d& p) {
    const Vector3d d = (box.min() - p).cwiseMax(p - box.max()).cwiseMax(0.0);
    return d.squaredNorm();
}

}  // namespace

SkinSurface::SkinSurface(const Matrix3X& positions, const Matrix3X& normals, std::span<const std::uint32_t> indices) {
    const auto n = static_cast<std::size_t>(positions.cols());
    m_positions.resize(n);
    m_normals.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        m_positions[i] = positions.col(static_cast<Eigen::Index>(i)).cast<double>();
        const Vector3d normal = i < static_cast<std::size_t>(normals.cols()) ? Vector3d(normals.col(static_cast<Eigen::Index>(i)).cast<double>())
                                                                             : Vector3d::Zero();
        m_normals[i] = normal.norm() > 1e-12 ? Vector3d(normal.normalized()) : Vector3d::Zero();
    }
    for (std::size_t f = 0; f + 2 < indices.size(); f += 3) {
        const std::array<std::uint32_t, 3> t{indices[f], indices[f + 1], indices[f + 2]};
        if (t[0] >= n || t[1] >= n || t[2] >= n) continue;
        const Vector3d& a = m_positions[t[0]];
        const double twice_area = (m_positions[t[1]] - a).cross(m_positions[t[2]] - a).norm();
        if (twice_area <= 1e-14) continue;  // no area, no normal
        m_triangles.push_back(t);
        m_area_m2 += twice_area / 2;
    }
    if (m_triangles.empty()) return;
    std::vector<Vector3d> centroids(m_triangles.size());
    for (std::size_t t = 0; t < m_triangles.size(); ++t)
        centroids[t] = (m_positions[m_triangles[t][0]] + m_positions[m_triangles[t][1]] + m_positions[m_triangles[t][2]]) / 3;
    m_order.resize(m_triangles.size());
    for (std::size_t t = 0; t < m_order.size(); ++t) m_order[t] = static_cast<std::uint32_t>(t);
    m_nodes.reserve(2 * m_triangles.size() / leaf_size + 2);
    build(0, static_cast<std::uint32_t>(m_order.size()), centroids);
}

std::uint32_t SkinSurface::build(std::uint32_t first, std::uint32_t count, std::vector<Vector3d>& centroids) {
    const auto index = static_cast<std::uint32_t>(m_nodes.size());
    m_nodes.emplace_back();
    Eigen::AlignedBox3d box, centre_box;
    for (std::uint32_t i = first; i < first + count; ++i) {
        for (std::uint32_t v : m_triangles[m_order[i]]) box.extend(m_positions[v]);
        centre_box.extend(centroids[m_order[i]]);
    }
    m_nodes[index].box = box;
    if (count <= leaf_size) {
        m_nodes[index].first = first;
        m_nodes[index].count = count;
        return index;
    }
    int axis = 0;
    centre_box.sizes().maxCoeff(&axis);
    const std::uint32_t half = count / 2;
    // Ties broken by index, so the tree (and every answer) is the same on every run.
    std::nth_element(m_order.begin() + first, m_order.begin() + first + half, m_order.begin() + first + count,
                     [&](std::uint32_t l, std::uint32_t r) {
                         return centroids[l][axis] != centroids[r][axis] ? centroids[l][axis] < centroids[r][axis] : l < r;
                     });
    build(first, half, centroids);  // the left child is index + 1
    const std::uint32_t right = build(first + half, count - half, centroids);
    m_nodes[index].first = right;
    m_nodes[index].count = 0;
    return index;
}

SkinSurface::Closest SkinSurface::closest(const Vector3d& p) const {
    Closest best;
    if (m_nodes.empty()) return best;
    double best_d2 = std::numeric_limits<double>::infinity();
    Vector3d best_bary = Vector3d::Zero();
    std::uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& node = m_nodes[stack[--top]];
        if (box_distance_squared(node.box, p) >= best_d2) continue;
        if (node.count > 0) {
            for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
                const auto& t = m_triangles[m_order[i]];
                const Vector3d bary = closest_barycentric(p, m_positions[t[0]], m_positions[t[1]], m_positions[t[2]]);
                const Vector3d q = bary[0] * m_positions[t[0]] + bary[1] * m_positions[t[1]] + bary[2] * m_positions[t[2]];
                const double d2 = (p - q).squaredNorm();
                if (d2 < best_d2 || (d2 == best_d2 && m_order[i] < best.triangle)) {
                    best_d2 = d2;
                    best.point = q;
                    best.triangle = m_order[i];
                    best_bary = bary;
                }
            }
            continue;
        }
        // Inner node: the left child is the next node; visit the nearer child first.
        const std::uint32_t self = static_cast<std::uint32_t>(&node - m_nodes.data());
        const std::uint32_t left = self + 1, right = node.first;
        const double dl = box_distance_squared(m_nodes[left].box, p), dr = box_distance_squared(m_nodes[right].box, p);
        if (top + 2 > 64) continue;  // deeper than any balanced tree of 2^60 faces
        if (dl < dr) {
            stack[top++] = right;
            stack[top++] = left;
        } else {
            stack[top++] = left;
            stack[top++] = right;
        }
    }
    const auto& t = m_triangles[static_cast<std::size_t>(best.triangle)];
    const Vector3d a = m_positions[t[0]], b = m_positions[t[1]], c = m_positions[t[2]];
    Vector3d normal = best_bary[0] * m_normals[t[0]] + best_bary[1] * m_normals[t[1]] + best_bary[2] * m_normals[t[2]];
    const Vector3d face = (b - a).cross(c - a).normalized();
    if (normal.norm() < 1e-9) normal = face;  // opposed vertex normals: the face decides
    best.normal = normal.normalized();
    best.weights = best_bary;
    best.distance_m = std::sqrt(best_d2);
    best.outside = (p - best.point).dot(best.normal) > 0;
    return best;
}

SkinSurface::Hit SkinSurface::first_hit(const Vector3d& o, const Vector3d& d) const {
    Hit best;
    if (m_nodes.empty()) return best;
    double nearest = std::numeric_limits<double>::infinity();
    const Vector3d inverse = d.cwiseInverse();  // an axis the ray is parallel to: +-inf
    // Where the ray is within a box, widened by a little so that rounding never drops a
    // face the box holds; a box entered past the nearest hit so far is left (one entered
    // at it may hold a face of lower index met there too).
    const auto enters_before = [&](const Eigen::AlignedBox3d& box) {
        double near = 0, far = nearest;
        for (int i = 0; i < 3; ++i) {
            const double slack = 1e-9 + 1e-9 * (std::abs(box.min()[i]) + std::abs(box.max()[i]));
            const double lo = box.min()[i] - slack, hi = box.max()[i] + slack;
            if (d[i] == 0) {
                if (o[i] < lo || o[i] > hi) return false;
                continue;
            }
            double t0 = (lo - o[i]) * inverse[i], t1 = (hi - o[i]) * inverse[i];
            if (t0 > t1) std::swap(t0, t1);
            near = std::max(near, t0);
            far = std::min(far, t1);
            if (near > far) return false;
        }
        return true;
    };
    std::uint32_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const std::uint32_t index = stack[--top];
        const Node& node = m_nodes[index];
        if (!enters_before(node.box)) continue;
        if (node.count == 0) {
            if (top + 2 > 64) continue;  // deeper than any balanced tree of 2^60 faces
            stack[top++] = node.first;
            stack[top++] = index + 1;
            continue;
        }
        for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
            const auto& tri = m_triangles[m_order[i]];
            const Vector3d &a = m_positions[tri[0]], &b = m_positions[tri[1]], &c = m_positions[tri[2]];
            const Vector3d e1 = b - a, e2 = c - a, q = d.cross(e2);
            const double det = e1.dot(q);
            if (std::abs(det) < 1e-14) continue;
            const Vector3d s = o - a;
            const double u = s.dot(q) / det;
            if (u < 0 || u > 1) continue;
            const Vector3d r = s.cross(e1);
            const double v = d.dot(r) / det;
            if (v < 0 || u + v > 1) continue;
            const double t = e2.dot(r) / det;
            if (t > 1e-9 && (t < nearest || (t == nearest && m_order[i] < best.triangle))) {
                nearest = t;
                best.t = t;
                best.triangle = m_order[i];
            }
        }
    }
    return best;
}

std::vector<SkinSample> sample_skin(const Matrix3X& positions, const Matrix3X& normals, std::span<const std::uint32_t> indices,
                                    double spacing_m) {
    std::vector<SkinSample> out;
    const auto n = static_cast<std::size_t>(positions.cols());
    out.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        SkinSample s;
        s.position = positions.col(static_cast<Eigen::Index>(i)).cast<double>();
        const Vector3d normal = normals.col(static_cast<Eigen::Index>(i)).cast<double>();
        s.normal = normal.norm() > 1e-12 ? Vector3d(normal.normalized()) : Vector3d::UnitY();
        s.vertex = static_cast<std::uint32_t>(i);
        s.is_vertex = true;
        out.push_back(s);
    }
    for (std::size_t f = 0; f + 2 < indices.size(); f += 3) {
        const std::uint32_t i0[3] = {indices[f], indices[f + 1], indices[f + 2]};
        if (i0[0] >= n || i0[1] >= n || i0[2] >= n) continue;
        const Vector3d p[3] = {out[i0[0]].position, out[i0[1]].position, out[i0[2]].position};
        const double longest = std::max({(p[1] - p[0]).norm(), (p[2] - p[1]).norm(), (p[0] - p[2]).norm()});
        if (longest <= 2 * spacing_m) continue;  // the corners are close enough
        const Vector3d face = (p[1] - p[0]).cross(p[2] - p[0]);
        const double area = face.norm() / 2;
        if (area <= 1e-14) continue;
        // One point per spacing^2 of area, spread by the R2 low-discrepancy sequence (Roberts)
        // folded into the triangle: even for long thin faces, and the same on every run.
        const auto count = static_cast<int>(std::ceil(area / (spacing_m * spacing_m)));
        constexpr double a1 = 0.7548776662466927, a2 = 0.5698402909980532;
        for (int i = 0; i < count; ++i) {
            double u = std::fmod(0.5 + a1 * (i + 1), 1.0), v = std::fmod(0.5 + a2 * (i + 1), 1.0);
            if (u + v > 1) {
                u = 1 - u;
                v = 1 - v;
            }
            const double w0 = 1 - u - v;
            SkinSample sample;
            sample.position = w0 * p[0] + u * p[1] + v * p[2];
            const Vector3d normal = w0 * out[i0[0]].normal + u * out[i0[1]].normal + v * out[i0[2]].normal;
            sample.normal = normal.norm() > 1e-9 ? Vector3d(normal.normalized()) : Vector3d(face.normalized());
            sample.vertex = w0 >= u && w0 >= v ? i0[0] : (u >= v ? i0[1] : i0[2]);
            sample.is_vertex = false;
            out.push_back(sample);
        }
    }
    return out;
}

}  // namespace drape
