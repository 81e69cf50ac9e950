// Ellipsoids fitted to skin samples. See ellipsoid_solver.hpp for the method.
#include "drape/systems/character/ellipsoid_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <atomic>
#include <memory>
#include <unordered_map>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <cstdlib>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace drape::fitting {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// f(i) for i in [0, n), in parallel blocks; f writes only its own outputs.
template <class F>
void for_each_index(std::size_t n, F&& f) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) f(i);
    });
}

// Rotation by the axis-angle vector w (Rodrigues).
Matrix3d exp_rotation(const Vector3d& w) {
    const double angle = w.norm();
    if (angle < 1e-12) return Matrix3d::Identity();
    return Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
}

// x beyond the margin, softened beyond `huber`: squared, it is the Huber cost of the excess.
double soft_excess(double x, double margin, double huber) {
    const double e = x - margin;
    if (e <= 0) return 0;
    if (e <= huber) return e;
    return std::sqrt(2 * huber * e - huber * huber);
}

// Principal axes (columns, a rotation; the largest spread last) of points, and their mean.
Matrix3d principal_axes(const std::vector<Vector3d>& points, Vector3d& mean) {
    mean = Vector3d::Zero();
    for (const Vector3d& p : points) mean += p;
    mean /= double(std::max<std::size_t>(1, points.size()));
    Matrix3d covariance = Matrix3d::Zero();
    for (const Vector3d& p : points) covariance += (p - mean) * (p - mean).transpose();
    Eigen::SelfAdjointEigenSolver<Matrix3d> eig(covariance);
    Matrix3d axes = eig.eigenvectors();
    if (!axes.allFinite()) axes.setIdentity();
    // A fixed sign per axis (largest component positive), so equal inputs give equal frames.
    for (int k = 0; k < 3; ++k) {
        Eigen::Index i = 0;
        axes.col(k).cwiseAbs().maxCoeff(&i);
        if (axes(i, k) < 0) axes.col(k) *= -1;
    }
    if (axes.determinant() < 0) axes.col(0) *= -1;
    return axes;
}

// Value at share q (0..1) of a list (partially sorts it).
double quantile(std::vector<double>& v, double q) {
    if (v.empty()) return 0;
    const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * double(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    return v[k];
}

// Points on the unit sphere, evenly spread (Fibonacci lattice).
std::vector<Vector3d> unit_sphere(int n) {
    std::vector<Vector3d> out(static_cast<std::size_t>(n));
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double y = 1.0 - 2.0 * (i + 0.5) / n;
        const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
        out[static_cast<std::size_t>(i)] = Vector3d(r * std::cos(golden * i), y, r * std::sin(golden * i));
    }
    return out;
}

// A first guess for a set of points: principal axes, centred on their (trimmed) box in
// that frame, radii half the box: the ellipsoid inscribed in the box.
Ellipsoid initial_shape(const std::vector<SkinSample>& samples, const std::vector<std::uint32_t>& subset, double min_radius) {
    std::vector<Vector3d> points;
    points.reserve(subset.size());
    for (std::uint32_t s : subset) points.push_back(samples[s].position);
    Vector3d mean;
    Ellipsoid e;
    e.axes = principal_axes(points, mean);
    Vector3d lo, hi;
    for (int k = 0; k < 3; ++k) {
        std::vector<double> along;
        along.reserve(points.size());
        for (const Vector3d& p : points) along.push_back(e.axes.col(k).dot(p - mean));
        lo[k] = quantile(along, 0.01);
        hi[k] = quantile(along, 0.99);
    }
    e.center = mean + e.axes * ((lo + hi) / 2);
    e.radii = ((hi - lo) / 2).cwiseMax(min_radius);
    return e;
}

// Samples bucketed in cubic cells, for the samples within a distance of a point.
class SampleGrid {
public:
    SampleGrid(const std::vector<SkinSample>& samples, double cell) : m_samples(samples), m_cell(cell) {
        for (std::uint32_t s = 0; s < samples.size(); ++s) m_cells[key(cell_of(samples[s].position))].push_back(s);
    }

    // Indices of the samples within `radius` of `c`, ascending.
    std::vector<std::uint32_t> within(const Vector3d& c, double radius) const {
        std::vector<std::uint32_t> out;
        const Eigen::Vector3i lo = cell_of(c - Vector3d::Constant(radius)), hi = cell_of(c + Vector3d::Constant(radius));
        const double cells = double(hi.x() - lo.x() + 1) * double(hi.y() - lo.y() + 1) * double(hi.z() - lo.z() + 1);
        const double r2 = radius * radius;
        if (cells > double(m_cells.size())) {  // a big query: every sample
            for (std::uint32_t s = 0; s < m_samples.size(); ++s)
                if ((m_samples[s].position - c).squaredNorm() <= r2) out.push_back(s);
            return out;
        }
        for (int x = lo.x(); x <= hi.x(); ++x)
            for (int y = lo.y(); y <= hi.y(); ++y)
                for (int z = lo.z(); z <= hi.z(); ++z) {
                    const auto it = m_cells.find(key({x, y, z}));
                    if (it == m_cells.end()) continue;
                    for (std::uint32_t s : it->second)
                        if ((m_samples[s].position - c).squaredNorm() <= r2) out.push_back(s);
                }
        std::sort(out.begin(), out.end());
        return out;
    }

private:
    Eigen::Vector3i cell_of(const Vector3d& p) const { return (p / m_cell).array().floor().cast<int>(); }
    static std::int64_t key(const Eigen::Vector3i& c) {
        return (std::int64_t(c.x() & 0x1fffff) << 42) | (std::int64_t(c.y() & 0x1fffff) << 21) | std::int64_t(c.z() & 0x1fffff);
    }
    const std::vector<SkinSample>& m_samples;
    double m_cell;
    std::unordered_map<std::int64_t, std::vector<std::uint32_t>> m_cells;
};

// The skin's signed distance (+ outside) on a regular grid, each grid point computed when
// first needed (the ellipsoids visit a small part of the box), trilinear in between.
// Values do not depend on the order of the queries, so the fit stays deterministic.
class DistanceField {
public:
    DistanceField(const SkinSurface& skin, const Eigen::AlignedBox3d& box, double spacing)
        : m_skin(skin), m_origin(box.min()), m_h(spacing) {
        for (int a = 0; a < 3; ++a) m_n[a] = std::max(2, static_cast<int>(std::ceil(box.sizes()[a] / spacing)) + 1);
        const std::size_t count = std::size_t(m_n[0]) * std::size_t(m_n[1]) * std::size_t(m_n[2]);
        m_values = std::make_unique<std::atomic<float>[]>(count);
        for (std::size_t i = 0; i < count; ++i) m_values[i].store(std::numeric_limits<float>::quiet_NaN(), std::memory_order_relaxed);
    }

    double operator()(const Vector3d& p) const {
        const Vector3d g = (p - m_origin) / m_h;
        int i[3];
        double t[3];
        for (int a = 0; a < 3; ++a) {
            const double f = std::floor(g[a]);
            if (f < 0 || f >= m_n[a] - 1) return exact(p);  // outside the grid
            i[a] = static_cast<int>(f);
            t[a] = g[a] - f;
        }
        double v = 0;
        for (int c = 0; c < 8; ++c) {
            const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
            const double w = (dx ? t[0] : 1 - t[0]) * (dy ? t[1] : 1 - t[1]) * (dz ? t[2] : 1 - t[2]);
            v += w * at(i[0] + dx, i[1] + dy, i[2] + dz);
        }
        return v;
    }

private:
    double exact(const Vector3d& p) const {
        const SkinSurface::Closest c = m_skin.closest(p);
        return c.outside ? c.distance_m : -c.distance_m;
    }
    // Threads may compute the same grid point at once; they store the same value.
    double at(int x, int y, int z) const {
        std::atomic<float>& slot = m_values[std::size_t(x) + std::size_t(m_n[0]) * (std::size_t(y) + std::size_t(m_n[1]) * std::size_t(z))];
        float v = slot.load(std::memory_order_relaxed);
        if (std::isnan(v)) {
            v = static_cast<float>(exact(m_origin + m_h * Vector3d(x, y, z)));
            slot.store(v, std::memory_order_relaxed);
        }
        return v;
    }

    const SkinSurface& m_skin;
    Vector3d m_origin;
    double m_h;
    int m_n[3];
    std::unique_ptr<std::atomic<float>[]> m_values;
};

struct Solver {
    const std::vector<SkinSample>& samples;
    const SolverSettings& settings;
    const DistanceField& field;
    const SampleGrid& grid;
    std::vector<Piece> pieces;
    std::vector<int> piece_of;             // the piece that answers for each sample (-1: none)
    std::vector<Vector3d> sphere = unit_sphere(128);
    double max_radius = 1;                 // half the extent of the whole skin
    double sample_area_m2 = 1e-4;          // skin area per sample

    // Samples within `reach` of a piece's centre, and its own.
    std::vector<std::uint32_t> candidates(std::size_t k, double reach) const {
        std::vector<std::uint32_t> out = grid.within(pieces[k].shape.center, reach);
        const std::size_t n = out.size();
        for (std::uint32_t s : pieces[k].samples) out.push_back(s);
        std::inplace_merge(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(n), out.end());
        out.erase(std::unique(out.begin(), out.end()), out.end());
        return out;
    }

    // Of the candidates, those piece k answers for: it is the nearest piece to them (the
    // deepest holding them, or the closest). One piece answers for each sample, so no two
    // leave a sample to each other, and while it answers a piece cannot drop a sample
    // without paying for it.
    std::vector<char> must_cover(std::size_t k, const std::vector<std::uint32_t>& near) const {
        std::vector<char> out(near.size(), 0);
        for_each_index(near.size(), [&](std::size_t i) {
            const Vector3d& p = samples[near[i]].position;
            const double own = signed_distance(pieces[k].shape, p);
            bool nearest = true;
            for (std::size_t j = 0; j < pieces.size() && nearest; ++j) {
                if (j == k) continue;
                // Far beyond piece j's bounding sphere it cannot be nearer (with room to spare
                // for the first-order distance).
                if ((p - pieces[j].shape.center).norm() - pieces[j].shape.radii.maxCoeff() > own + 0.05) continue;
                const double d = signed_distance(pieces[j].shape, p);
                nearest = d > own || (d == own && j > k);
            }
            out[i] = nearest;
        });
        return out;
    }

    // The pieces other than k that may hold a point of `e`'s surface (piece k's shape, or
    // one tried for it): those whose bounding sphere comes near e's, with a centimetre to
    // spare (far beyond rounding). A point of e's surface lies within e's largest radius of
    // its centre, so no other piece can hold it.
    std::vector<std::size_t> neighbours(std::size_t k, const Ellipsoid& e) const {
        std::vector<std::size_t> out;
        for (std::size_t j = 0; j < pieces.size(); ++j) {
            if (j == k) continue;
            const Ellipsoid& o = pieces[j].shape;
            if ((o.center - e.center).norm() <= o.radii.maxCoeff() + e.radii.maxCoeff() + 0.01) out.push_back(j);
        }
        return out;
    }

    // Whether a point of a surface is inside one of `others` (then it is not on the union's
    // surface).
    bool buried(const std::vector<std::size_t>& others, const Vector3d& x) const {
        return std::any_of(others.begin(), others.end(), [&](std::size_t j) {
            const Ellipsoid& o = pieces[j].shape;
            return (o.axes.transpose() * (x - o.center)).cwiseQuotient(o.radii).squaredNorm() < 1;
        });
    }

    // Residuals of a shape for piece k: cover per candidate, then bulge per surface point.
    void residuals(std::size_t k, const Ellipsoid& e, const std::vector<std::uint32_t>& near, const std::vector<char>& cover,
                   const std::vector<double>& scale, Eigen::VectorXd& r) const {
        const std::size_t m = sphere.size();
        const Piece& piece = pieces[k];
        r.resize(static_cast<Eigen::Index>(near.size() + (piece.limited_reach ? 3 : 2) * m));
        for (std::size_t i = 0; i < near.size(); ++i) {
            const SkinSample& s = samples[near[i]];
            if (!cover[i]) {
                r[Eigen::Index(i)] = 0;
                continue;
            }
            // First-order, rescaled to the exact distance at the start of the fit (the first-
            // order one is poor beside a flat ellipsoid's rim; the exact one is costly).
            const double d = std::max(0.0, signed_distance(e, s.position)) * scale[i];
            r[Eigen::Index(i)] = (s.is_vertex ? 1.0 : settings.face_sample_weight) * soft_excess(d, settings.cover_margin_m, settings.huber_m);
        }
        const double unit_area = 4 * std::numbers::pi / double(m) * e.radii.prod();
        const std::vector<std::size_t> others = neighbours(k, e);
        for (std::size_t i = 0; i < m; ++i) {
            const Vector3d x = e.center + e.axes * e.radii.cwiseProduct(sphere[i]);
            double loose = 0, tight = 0;
            if (!buried(others, x)) {
                const double area = unit_area * sphere[i].cwiseQuotient(e.radii).norm();
                const double out = field(x);
                loose = std::sqrt(settings.bulge_weight * area / sample_area_m2) * soft_excess(out, settings.bulge_free_m + pieces[k].extra_free_m, settings.huber_m);
                tight = std::sqrt(settings.tight_weight * area / sample_area_m2) * soft_excess(out, 0, settings.huber_m);
            }
            r[Eigen::Index(near.size() + 2 * i)] = loose;
            r[Eigen::Index(near.size() + 2 * i + 1)] = tight;
            if (piece.limited_reach) {
                const double along = piece.reach_axis.dot(x);
                const double past = std::max(along - piece.reach_hi, piece.reach_lo - along) - piece.reach_m;
                const double area = unit_area * sphere[i].cwiseQuotient(e.radii).norm();
                r[Eigen::Index(near.size() + 2 * m + i)] = std::sqrt(settings.bulge_weight * area / sample_area_m2) * soft_excess(past, 0, settings.huber_m);
            }
        }
    }

    Ellipsoid apply(const Ellipsoid& base, const Eigen::Matrix<double, 9, 1>& x) const {
        Ellipsoid e;
        e.center = base.center + x.head<3>();
        e.axes = base.axes * exp_rotation(x.segment<3>(3));
        e.radii = (base.radii.array() * x.tail<3>().array().exp()).matrix().cwiseMax(settings.min_radius_m).cwiseMin(max_radius);
        return e;
    }

    // Levenberg-Marquardt on centre, rotation increment and log radii.
    Ellipsoid optimise(std::size_t k, const Ellipsoid& start, const std::vector<std::uint32_t>& near, const std::vector<char>& cover) const {
        std::vector<double> scale(near.size(), 1.0);
        for (std::size_t i = 0; i < near.size(); ++i) {
            if (!cover[i]) continue;
            const double first_order = signed_distance(start, samples[near[i]].position);
            if (first_order > 1e-6) scale[i] = outside_distance(start, samples[near[i]].position) / first_order;
        }
        using Vec9 = Eigen::Matrix<double, 9, 1>;
        using Mat9 = Eigen::Matrix<double, 9, 9>;
        Ellipsoid current = start;
        Eigen::VectorXd r, r_trial;
        residuals(k, current, near, cover, scale, r);
        double cost = r.squaredNorm();
        double lambda = 1e-3;
        constexpr double step = 1e-4;
        Eigen::MatrixXd J(r.size(), 9);
        for (int iteration = 0; iteration < settings.iterations && cost > 0; ++iteration) {
            // The columns in parallel: each is one more evaluation of the residuals.
            tbb::parallel_for(0, 9, [&](int p) {
                Vec9 x = Vec9::Zero();
                x[p] = step;
                Eigen::VectorXd r_step;
                residuals(k, apply(current, x), near, cover, scale, r_step);
                J.col(p) = (r_step - r) / step;
            });
            // Coefficient by coefficient (lazyProduct): Eigen's blocked product splits the
            // long sums where the CPU's cache sizes say, and rounds otherwise on another CPU.
            const Mat9 H = J.transpose().lazyProduct(J);
            const Vec9 g = J.transpose().lazyProduct(r);
            bool improved = false;
            while (lambda < 1e10) {
                Mat9 A = H;
                A.diagonal() += lambda * H.diagonal() + Vec9::Constant(1e-12);
                const Vec9 x = A.ldlt().solve(-g);
                if (!x.allFinite()) { lambda *= 10; continue; }
                const Ellipsoid trial = apply(current, x);
                residuals(k, trial, near, cover, scale, r_trial);
                const double trial_cost = r_trial.squaredNorm();
                if (trial_cost < cost) {
                    const double gain = (cost - trial_cost) / cost;
                    current = trial;
                    r.swap(r_trial);
                    cost = trial_cost;
                    lambda = std::max(1e-7, lambda * 0.3);
                    improved = gain > 1e-4;
                    break;
                }
                lambda *= 10;
            }
            if (!improved) break;
        }
        return current;
    }

    // Refits piece k. The samples near it are gathered again when the fit outgrew them (an
    // ellipsoid may only grow into skin it has been shown).
    void fit(std::size_t k) {
        for (int round = 0; round < 3; ++round) {
            const Ellipsoid start = pieces[k].shape;
            const double reach = start.radii.maxCoeff() + std::max(0.04, 0.5 * start.radii.maxCoeff());
            const std::vector<std::uint32_t> near = candidates(k, reach);
            const std::vector<char> cover = must_cover(k, near);
            const Ellipsoid fitted = optimise(k, start, near, cover);
            const bool outgrew = (fitted.center - start.center).norm() + fitted.radii.maxCoeff() > reach;
            pieces[k].shape = fitted;
            if (!outgrew) break;
        }
    }

    void sweep() {
        for (std::size_t k = 0; k < pieces.size(); ++k) fit(k);
    }

    // What each piece fails: the samples it answers for that lie farther than the tolerance
    // from every piece (vertices count 1, face samples less), and the area of its part of
    // the union's surface that stands out more than the bulge limit.
    struct Failures {
        std::vector<double> uncovered;                      // per piece, weighted count
        std::vector<std::vector<std::uint32_t>> samples;    // per piece, the uncovered samples
        std::vector<double> bulging_m2;                     // per piece
        double uncovered_total = 0, weight = 0, surface_m2 = 0;  // weight: of all samples
    };
    Failures failures() {
        Failures f;
        f.uncovered.assign(pieces.size(), 0);
        f.samples.resize(pieces.size());
        f.bulging_m2.assign(pieces.size(), 0);
        // Per sample (in parallel): the distance to the union and the nearest piece.
        std::vector<double> gap(samples.size());
        std::vector<std::size_t> nearest_of(samples.size());
        for_each_index(samples.size(), [&](std::size_t s) {
            double best = std::numeric_limits<double>::infinity();
            std::size_t nearest = 0;
            for (std::size_t k = 0; k < pieces.size(); ++k) {
                const double d = signed_distance(pieces[k].shape, samples[s].position);
                if (d < best) { best = d; nearest = k; }
            }
            // The first-order distance is only good near a surface; judge a miss exactly.
            if (best > 0) {
                best = std::numeric_limits<double>::infinity();
                for (const Piece& piece : pieces)
                    if ((samples[s].position - piece.shape.center).norm() - piece.shape.radii.maxCoeff() < best)
                        best = std::min(best, outside_distance(piece.shape, samples[s].position));
            }
            gap[s] = best;
            nearest_of[s] = nearest;
        });
        for (std::uint32_t s = 0; s < samples.size(); ++s) {
            const double weight = samples[s].is_vertex ? 1.0 : settings.face_sample_weight;
            f.weight += weight;
            if (gap[s] <= settings.coverage_tolerance_m) continue;
            f.uncovered[nearest_of[s]] += weight;
            f.uncovered_total += weight;
            f.samples[nearest_of[s]].push_back(s);
        }
        for (std::size_t k = 0; k < pieces.size(); ++k) {
            const Ellipsoid& e = pieces[k].shape;
            const double unit_area = 4 * std::numbers::pi / double(sphere.size()) * e.radii.prod();
            const std::vector<std::size_t> others = neighbours(k, e);
            for (const Vector3d& u : sphere) {
                const Vector3d x = e.center + e.axes * e.radii.cwiseProduct(u);
                if (buried(others, x)) continue;
                const double area = unit_area * u.cwiseQuotient(e.radii).norm();
                f.surface_m2 += area;
                if (field(x) > settings.bulge_limit_m) f.bulging_m2[k] += area;
            }
        }
        return f;
    }

    // A new piece for skin piece k leaves uncovered (a thumb, an ankle between a shin and a
    // foot): the largest connected patch of its uncovered samples (neighbours closer than the
    // tolerance twice over), with the skin within that distance, is where it starts.
    bool bud(std::size_t k, const std::vector<std::uint32_t>& uncovered) {
        if (uncovered.empty()) return false;
        const double link = 2.5 * settings.coverage_tolerance_m;
        std::vector<char> open(samples.size(), 0);
        for (std::uint32_t u : uncovered) open[u] = 1;
        std::vector<std::uint32_t> best;
        double best_weight = 0;
        for (std::uint32_t seed : uncovered) {
            if (!open[seed]) continue;
            std::vector<std::uint32_t> patch{seed};
            open[seed] = 0;
            double weight = 0;
            for (std::size_t i = 0; i < patch.size(); ++i) {
                weight += samples[patch[i]].is_vertex ? 1.0 : settings.face_sample_weight;
                for (std::uint32_t s : grid.within(samples[patch[i]].position, link))
                    if (open[s]) {
                        open[s] = 0;
                        patch.push_back(s);
                    }
            }
            if (weight > best_weight) {
                best_weight = weight;
                best = std::move(patch);
            }
        }
        if (best.empty()) return false;
        // The skin around the patch, reaching farther on a coarse mesh until there is enough
        // of it to start an ellipsoid from.
        std::vector<std::uint32_t> own;
        for (double reach = link; own.size() < 8 && reach <= 16 * link; reach *= 2) {
            std::vector<char> taken(samples.size(), 0);
            own.clear();
            for (std::uint32_t u : best)
                for (std::uint32_t s : grid.within(samples[u].position, reach))
                    if (!taken[s]) {
                        taken[s] = 1;
                        own.push_back(s);
                    }
        }
        std::sort(own.begin(), own.end());
        if (own.size() < 8) return false;
        Piece piece;
        piece.part = pieces[k].part;
        piece.samples = own;
        piece.shape = initial_shape(samples, own, settings.min_radius_m);
        pieces.push_back(std::move(piece));
        fit(pieces.size() - 1);
        fit(k);
        fit(pieces.size() - 1);
        return true;
    }

    // Splits piece k in two by 2-means of its samples; false when a half would be too small.
    bool split(std::size_t k) {
        const std::vector<std::uint32_t> own = pieces[k].samples;
        if (own.size() < 16) return false;
        std::vector<Vector3d> points;
        for (std::uint32_t s : own) points.push_back(samples[s].position);
        Vector3d mean;
        const Matrix3d axes = principal_axes(points, mean);
        std::vector<double> along;
        for (const Vector3d& p : points) along.push_back(axes.col(2).dot(p - mean));
        std::vector<double> sorted = along;
        const double median = quantile(sorted, 0.5);
        std::vector<int> side(points.size());
        for (std::size_t i = 0; i < points.size(); ++i) side[i] = along[i] > median ? 1 : 0;
        for (int iteration = 0; iteration < 10; ++iteration) {
            Vector3d c[2] = {Vector3d::Zero(), Vector3d::Zero()};
            std::size_t n[2] = {0, 0};
            for (std::size_t i = 0; i < points.size(); ++i) {
                c[side[i]] += points[i];
                ++n[side[i]];
            }
            if (n[0] == 0 || n[1] == 0) return false;
            c[0] /= double(n[0]);
            c[1] /= double(n[1]);
            bool changed = false;
            for (std::size_t i = 0; i < points.size(); ++i) {
                const int s = (points[i] - c[1]).squaredNorm() < (points[i] - c[0]).squaredNorm() ? 1 : 0;
                changed = changed || s != side[i];
                side[i] = s;
            }
            if (!changed) break;
        }
        std::vector<std::uint32_t> halves[2];
        for (std::size_t i = 0; i < own.size(); ++i) halves[side[i]].push_back(own[i]);
        if (halves[0].size() < 8 || halves[1].size() < 8) return false;
        Piece second;
        second.part = pieces[k].part;
        second.samples = halves[1];
        second.shape = initial_shape(samples, halves[1], settings.min_radius_m);
        pieces[k].samples = halves[0];
        pieces[k].shape = initial_shape(samples, halves[0], settings.min_radius_m);
        pieces.push_back(std::move(second));
        for (std::uint32_t s : pieces[k].samples) piece_of[s] = static_cast<int>(k);
        for (std::uint32_t s : pieces.back().samples) piece_of[s] = static_cast<int>(pieces.size() - 1);
        fit(k);
        fit(pieces.size() - 1);
        fit(k);
        return true;
    }
};

}  // namespace

double signed_distance(const Ellipsoid& e, const Vector3d& p) noexcept {
    const Vector3d q = e.axes.transpose() * (p - e.center);
    const double k0 = q.cwiseQuotient(e.radii).norm();
    const double k1 = q.cwiseQuotient(e.radii.cwiseProduct(e.radii)).norm();
    if (k1 < 1e-300) return -e.radii.minCoeff();
    return k0 * (k0 - 1) / k1;
}

double outside_distance(const Vector3d& radii, const Vector3d& q) noexcept {
    // Eberly, "Distance from a point to an ellipse, an ellipsoid, or a hyperellipsoid": the
    // closest point is x_i = r_i^2 y_i / (t + r_i^2) for the root t > 0 of
    // F(t) = sum (r_i y_i / (t + r_i^2))^2 - 1, which falls monotonically from F(0) > 0
    // (outside) and is <= 0 at t = |r * y|. Newton from the left converges (F is convex
    // there); bisection keeps it bracketed.
    const Vector3d y = q.cwiseAbs();
    if (y.cwiseQuotient(radii).squaredNorm() <= 1) return 0;
    const Vector3d r2 = radii.cwiseProduct(radii), ry = radii.cwiseProduct(y);
    // Bracket: F(t) >= (r_i y_i / (t + r_i^2))^2 for each i, so the root is past r_i y_i - r_i^2.
    double lo = std::max(0.0, (ry - r2).maxCoeff()), hi = ry.norm(), t = lo;
    for (int i = 0; i < 64; ++i) {
        const Vector3d ratio = ry.cwiseQuotient(r2 + Vector3d::Constant(t));
        const double f = ratio.squaredNorm() - 1;
        if (std::abs(f) < 1e-12) break;
        if (f > 0) lo = t;
        else hi = t;
        const double derivative = -2 * (ratio.array().square() / (r2 + Vector3d::Constant(t)).array()).sum();
        double next = derivative < 0 ? t - f / derivative : hi;
        if (!(next > lo && next < hi)) next = (lo + hi) / 2;
        if (hi - lo < 1e-15 * std::max(1.0, hi) || std::abs(next - t) < 1e-13 * std::max(1.0, t)) break;
        t = next;
    }
    const Vector3d x = r2.cwiseProduct(y).cwiseQuotient(r2 + Vector3d::Constant(t));
    return (x - y).norm();
}

double outside_distance(const Ellipsoid& e, const Vector3d& p) noexcept {
    return outside_distance(e.radii, e.axes.transpose() * (p - e.center));
}

std::vector<Piece> fit_pieces(const SkinSurface& skin, const std::vector<SkinSample>& samples, const std::vector<int>& part_of,
                              const std::vector<PartInfo>& part_info, const SolverSettings& settings) {
    if (samples.empty()) return {};
    Eigen::AlignedBox3d extent;
    for (const SkinSample& s : samples) extent.extend(s.position);
    const double size = extent.sizes().maxCoeff();
    Eigen::AlignedBox3d box = extent;
    box.extend(extent.min() - Vector3d::Constant(0.1 * size));
    box.extend(extent.max() + Vector3d::Constant(0.1 * size));
    DistanceField field(skin, box, settings.field_spacing_m);
    const SampleGrid grid(samples, 0.03);
    Solver solver{samples, settings, field, grid, {}, std::vector<int>(samples.size(), -1)};
    solver.max_radius = std::max(settings.min_radius_m, 0.5 * size);
    solver.sample_area_m2 = std::max(1e-8, skin.area_m2() / double(samples.size()));

    int parts = 0;
    for (int p : part_of) parts = std::max(parts, p + 1);
    std::vector<std::vector<std::uint32_t>> of_part(static_cast<std::size_t>(parts));
    for (std::uint32_t s = 0; s < samples.size(); ++s)
        if (part_of[s] >= 0) of_part[static_cast<std::size_t>(part_of[s])].push_back(s);
    for (int p = 0; p < parts; ++p) {
        auto& own = of_part[static_cast<std::size_t>(p)];
        if (own.size() < 4) continue;
        Piece piece;
        piece.part = p;
        piece.samples = own;
        piece.shape = initial_shape(samples, own, settings.min_radius_m);
        if (static_cast<std::size_t>(p) < part_info.size() && part_info[static_cast<std::size_t>(p)].limited_reach) {
            piece.limited_reach = true;
            Eigen::Index longest = 0;
            piece.shape.radii.maxCoeff(&longest);
            piece.reach_axis = piece.shape.axes.col(longest);
            piece.reach_lo = std::numeric_limits<double>::infinity();
            piece.reach_hi = -piece.reach_lo;
            for (std::uint32_t s : own) {
                const double along = piece.reach_axis.dot(samples[s].position);
                piece.reach_lo = std::min(piece.reach_lo, along);
                piece.reach_hi = std::max(piece.reach_hi, along);
            }
            piece.reach_m = part_info[static_cast<std::size_t>(p)].reach_m;
        }
        for (std::uint32_t s : own) solver.piece_of[s] = static_cast<int>(solver.pieces.size());
        solver.pieces.push_back(std::move(piece));
    }
    if (solver.pieces.empty()) return {};
    for (int i = 0; i < settings.sweeps; ++i) solver.sweep();

    // While the budget allows, the piece that fails most gets help: a new piece where it
    // leaves skin uncovered, or a split where it stands out; its mirror on the other side
    // the same when that fails too. A piece's failure is measured against what the whole
    // body may fail: half a per cent of the skin uncovered, 5 % of the surface bulging.
    std::vector<char> stuck;
    while (static_cast<int>(solver.pieces.size()) < settings.max_pieces) {
        const Solver::Failures f = solver.failures();
        auto cover_score = [&](std::size_t k) { return f.uncovered[k] / std::max(1.0, 0.005 * f.weight); };
        auto bulge_score = [&](std::size_t k) { return f.bulging_m2[k] / std::max(1e-9, 0.05 * f.surface_m2); };
        auto score = [&](std::size_t k) { return cover_score(k) + bulge_score(k); };
        stuck.resize(solver.pieces.size(), 0);
        std::size_t worst = solver.pieces.size();
        for (std::size_t k = 0; k < solver.pieces.size(); ++k)
            if (!stuck[k] && (worst == solver.pieces.size() || score(k) > score(worst))) worst = k;
        if (worst == solver.pieces.size() || score(worst) < settings.split_threshold) break;
        // Done when the body as a whole is within its allowance.
        double bulging = 0;
        for (double b : f.bulging_m2) bulging += b;
        if (f.uncovered_total <= settings.target_uncovered * f.weight && bulging <= settings.target_bulging * f.surface_m2) break;
        auto help = [&](std::size_t k) {
            const auto part = static_cast<std::size_t>(solver.pieces[k].part);
            if (part < part_info.size() && !part_info[part].may_split) return false;
            return cover_score(k) >= bulge_score(k) ? solver.bud(k, f.samples[k]) || solver.split(k) : solver.split(k);
        };
        if (!help(worst)) {
            stuck[worst] = 1;
            continue;
        }
        const int part = solver.pieces[worst].part;
        const int mirror = part >= 0 && part < static_cast<int>(part_info.size()) ? part_info[static_cast<std::size_t>(part)].mirror : -1;
        if (mirror < 0 || static_cast<int>(solver.pieces.size()) >= settings.max_pieces) continue;
        std::size_t twin = f.uncovered.size();
        for (std::size_t k = 0; k < f.uncovered.size(); ++k)
            if (solver.pieces[k].part == mirror && (twin == f.uncovered.size() || score(k) > score(twin))) twin = k;
        if (twin < f.uncovered.size() && score(twin) >= 0.5 * settings.split_threshold) (void)help(twin);
    }
    for (int i = 0; i < settings.sweeps; ++i) solver.sweep();

    // Coverage comes first (a garment must not slip into the body): where the budget is
    // spent and skin is still uncovered, the pieces that leave it may stand out further,
    // a step at a time.
    for (int step = 0; step < settings.relax_steps; ++step) {
        const Solver::Failures f = solver.failures();
        if (f.uncovered_total <= settings.target_uncovered * f.weight) break;
        bool relaxed = false;
        for (std::size_t k = 0; k < solver.pieces.size(); ++k)
            if (f.uncovered[k] > 0.1 * 0.005 * f.weight) {
                solver.pieces[k].extra_free_m += settings.relax_step_m;
                relaxed = true;
            }
        if (!relaxed) break;
        solver.sweep();
    }
    return std::move(solver.pieces);
}

}  // namespace drape::fitting
