// Particle-ellipsoid collision (method §5); step order in collision.hpp.
#include "systems/cloth/collision.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "systems/cloth/body.hpp"

namespace drape {
namespace {

// A pushed-out particle sits this fraction outside the surface so that float rounding
// cannot leave it a hair inside: 1e-6 of the radius, more far from the world origin where
// a float position has fewer digits (at 10 m, 1 ulp is ~1 um).
inline Real surface_clearance(const EllipsoidFrame& f) {
    const Real reach = f.center.cwiseAbs().maxCoeff() + f.radii_m.maxCoeff();
    return Real(1e-6) + 8 * std::numeric_limits<Real>::epsilon() * reach / f.radii_m.minCoeff();
}
// Re-test rounds for a particle pushed between overlapping ellipsoids, before the fallback.
constexpr int max_retest_rounds = 4;

// Where a particle at unit-sphere image y leaves the ellipsoid along its centre line
// (method §5): on the surface plus a clearance. At the centre there is no centre line; it
// leaves along the longest axis. Returns the unit-sphere image of the new place.
inline Vec3 place_on_surface(const EllipsoidFrame& f, const Vec3& y_in, Vec3& x) {
    Vec3 y = y_in;
    Real length = y.norm();
    if (length <= Real(1e-6)) {
        Eigen::Index axis = 0;
        f.radii_m.maxCoeff(&axis);
        y = Vec3::Unit(axis);
        length = 1;
    }
    const Vec3 y_surface = y * ((1 + surface_clearance(f)) / length);
    x = f.center + f.rotation * f.radii_m.cwiseProduct(y_surface);
    return y_surface;
}

// A centre-line push-out shorter than this share of the smallest radius is taken as it is:
// near the surface the centre line and the normal agree to within a fraction of it.
constexpr Real shallow_share = Real(0.25);

// The response of one contact (method §5): onto the surface along the centre line, or
// along the outward normal at the particle when that way out is shorter. Deep inside an
// elongated ellipsoid (a thigh the hem swung into) the centre line runs along the long axis
// and would carry the particle tens of centimetres toward the knee; the normal leaves by
// the short side. Returns the unit-sphere image of the new place.
inline Vec3 place_shortest(const EllipsoidFrame& f, const Vec3& y, Vec3& x) {
    const Real y_sq = y.squaredNorm();
    if (y_sq > Real(1e-12)) {
        const Real along_centre = (x - f.center).norm() * (1 / std::sqrt(y_sq) - 1);
        if (along_centre > shallow_share * f.radii_m.minCoeff()) {
            // Along the normal n = L^T y (L = to_unit): the unit-sphere image moves along d = L n,
            // |y + s d| = 1 at s = -2c / (b + sqrt(b^2 - 4ac)) with a = |d|^2, b = 2 y.d = 2 |n|^2,
            // c = |y|^2 - 1 < 0 (the form without cancellation); the world move is s |n|.
            const Vec3 n = f.to_unit.transpose() * y;
            const Vec3 d = f.to_unit * n;
            const Real a = d.squaredNorm(), b = 2 * n.squaredNorm(), c = y_sq - 1;
            const Real s = -2 * c / (b + std::sqrt(b * b - 4 * a * c));
            if (s * n.norm() < along_centre) return place_on_surface(f, y + s * d, x);
        }
    }
    return place_on_surface(f, y, x);
}

// Inelastic contact (method §5): no velocity into the surface, relative to its motion.
inline void remove_approach(const EllipsoidFrame& f, const Vec3& y_surface, const Vec3& x, Vec3& v) {
    const Vec3 normal = (f.to_unit.transpose() * y_surface).normalized();
    const Vec3 surface_velocity = body_velocity_at(f, x);
    const Real approach = (v - surface_velocity).dot(normal);
    if (approach < 0) v -= approach * normal;
}

template <class F>
inline void for_each_bit(std::uint64_t bits, F&& f) {
    while (bits != 0) {
        const int e = std::countr_zero(bits);
        bits &= bits - 1;
        f(e);
    }
}

// ---- Detection (method §5): the unit-sphere test, 8 consecutive particles at a time.

constexpr Eigen::Index detect_lanes = 8;
using DetectLanes = Eigen::Array<Real, detect_lanes, 1>;
using LaneBits = std::array<std::uint64_t, detect_lanes>;

// Bit e of hits[l] is set when ellipsoid e is in tested[l] and contains particle begin + l
// (|y| < 1). Every ellipsoid in any of the lists is tested against the whole block in one
// pass of vector instructions; lanes whose list leaves it out are discarded. Brute force's
// reference detection uses the same arithmetic, so both agree to the bit.
inline void detect_block(const Matrix3X& x, Eigen::Index begin, Eigen::Index count,
                         std::span<const EllipsoidFrame> frames, const LaneBits& tested, LaneBits& hits) {
    DetectLanes p0 = DetectLanes::Zero(), p1 = DetectLanes::Zero(), p2 = DetectLanes::Zero();
    std::uint64_t any = 0;
    for (Eigen::Index l = 0; l < count; ++l) {
        p0[l] = x(0, begin + l);
        p1[l] = x(1, begin + l);
        p2[l] = x(2, begin + l);
        any |= tested[static_cast<std::size_t>(l)];
    }
    hits.fill(0);
    for_each_bit(any, [&](int e) {
        const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
        const Mat3& m = f.to_unit;
        const DetectLanes d0 = p0 - f.center[0], d1 = p1 - f.center[1], d2 = p2 - f.center[2];
        const DetectLanes y0 = m(0, 0) * d0 + m(0, 1) * d1 + m(0, 2) * d2;
        const DetectLanes y1 = m(1, 0) * d0 + m(1, 1) * d1 + m(1, 2) * d2;
        const DetectLanes y2 = m(2, 0) * d0 + m(2, 1) * d1 + m(2, 2) * d2;
        const DetectLanes y_sq = y0 * y0 + y1 * y1 + y2 * y2;
        const std::uint64_t bit = std::uint64_t(1) << e;
        for (std::size_t l = 0; l < static_cast<std::size_t>(detect_lanes); ++l)
            hits[l] |= y_sq[static_cast<Eigen::Index>(l)] < 1 ? tested[l] & bit : 0;
    });
}

// ---- Candidate lists (method §5, spatial locality); see collision.hpp step 1.

// An ellipsoid's bit is refreshed in every list once the ellipsoid has moved this share of
// the margin since its reference pose; a particle's list is refreshed when its own move
// plus that of an unlisted ellipsoid reaches the clearance between their references. docs/cloth.md has the measurements.
constexpr Real ellipsoid_refresh_share = Real(0.5);
// Particles per block in a bit refresh; a block whose bounding box is farther than the
// margin from the ellipsoid's box is cleared without a test.
constexpr Eigen::Index candidate_block = 32;
// Clearances are lowered by this much so that float rounding cannot turn a bound into a miss.
constexpr Real clearance_rounding_m = Real(1e-5);

// An ellipsoid as the list tests see it: unit-sphere map and world box, in the frame of the
// points it is tested against.
struct ListEllipsoid {
    Mat3 to_unit = Mat3::Identity();
    Vec3 offset = Vec3::Zero();  ///< to_unit * centre.
    Vec3 radii = Vec3::Ones();
    Vec3 low = Vec3::Zero(), high = Vec3::Zero();

    ListEllipsoid() = default;
    explicit ListEllipsoid(const EllipsoidFrame& f)
        : to_unit(f.to_unit), offset(f.to_unit * f.center), radii(f.radii_m) {
        const Vec3 half = f.rotation.cwiseAbs() * f.radii_m;
        low = f.center - half;
        high = f.center + half;
    }
};

// Lower bounds of the distances from points to an ellipsoid, from their unit-sphere
// coordinates y (3 x k): the unit-sphere map stretches distances by at most 1 / r_min, and
// the ellipsoid lies inside its box of half sizes r_i in its own axes. Negative inside.
template <class Y>
inline auto clearance_of(const Y& y, const Vec3& radii) {
    const auto box = ((y.array().abs() - 1).colwise() * radii.array()).colwise().maxCoeff();
    return (radii.minCoeff() * (y.colwise().norm().array() - 1)).max(box);
}

// Ellipsoids as structure of arrays, 8 to a chunk, to test one point against all of them
// in a few vector instructions (a particle's whole list). Unused lanes hold an ellipsoid
// 1e18 m away: never listed, never the nearest.
class EllipsoidLanes {
public:
    void add(const ListEllipsoid& f, int e) {
        const int chunk = m_count / width, lane = m_count % width;
        if (lane == 0) m_chunks[static_cast<std::size_t>(chunk)] = Chunk{};
        Chunk& c = m_chunks[static_cast<std::size_t>(chunk)];
        for (int i = 0; i < 9; ++i) c.to_unit[static_cast<std::size_t>(i)][lane] = f.to_unit(i / 3, i % 3);
        for (int i = 0; i < 3; ++i) {
            c.offset[static_cast<std::size_t>(i)][lane] = f.offset[i];
            c.radii[static_cast<std::size_t>(i)][lane] = f.radii[i];
        }
        c.r_min[lane] = f.radii.minCoeff();
        c.bit[static_cast<std::size_t>(lane)] = std::uint64_t(1) << e;
        ++m_count;
    }
    [[nodiscard]] bool empty() const noexcept { return m_count == 0; }

    // Sets `bits` to the ellipsoids within `margin` of x and `out[e]` to the clearance
    // (clearance_of) of each other ellipsoid e, +inf for the listed ones.
    void test(const Vec3& x, Real margin, std::uint64_t& bits, std::array<Real, 64>& out) const {
        bits = 0;
        for (int k = 0; k * width < m_count; ++k) {
            const Chunk& c = m_chunks[static_cast<std::size_t>(k)];
            const Lanes y0 = c.to_unit[0] * x[0] + c.to_unit[1] * x[1] + c.to_unit[2] * x[2] - c.offset[0];
            const Lanes y1 = c.to_unit[3] * x[0] + c.to_unit[4] * x[1] + c.to_unit[5] * x[2] - c.offset[1];
            const Lanes y2 = c.to_unit[6] * x[0] + c.to_unit[7] * x[1] + c.to_unit[8] * x[2] - c.offset[2];
            const Lanes sphere = c.r_min * ((y0 * y0 + y1 * y1 + y2 * y2).sqrt() - 1);  // as clearance_of
            const Lanes box0 = c.radii[0] * (y0.abs() - 1), box1 = c.radii[1] * (y1.abs() - 1), box2 = c.radii[2] * (y2.abs() - 1);
            const Lanes clearance = sphere.max(box0).max(box1.max(box2));
            const auto listed = clearance <= margin;
            const Lanes unlisted = listed.select(Lanes::Constant(std::numeric_limits<Real>::infinity()), clearance);
            for (int l = 0; l < width && k * width + l < m_count; ++l) {
                const std::uint64_t bit = c.bit[static_cast<std::size_t>(l)];
                out[static_cast<std::size_t>(std::countr_zero(bit))] = unlisted[l];
                bits |= listed[l] ? bit : 0;
            }
        }
    }

private:
    static constexpr int width = 8;
    using Lanes = Eigen::Array<Real, width, 1>;
    struct Chunk {
        std::array<Lanes, 9> to_unit{Lanes::Zero(), Lanes::Zero(), Lanes::Zero(), Lanes::Zero(), Lanes::Zero(),
                                     Lanes::Zero(), Lanes::Zero(), Lanes::Zero(), Lanes::Zero()};
        std::array<Lanes, 3> offset{Lanes::Constant(Real(-1e18)), Lanes::Zero(), Lanes::Zero()};
        std::array<Lanes, 3> radii{Lanes::Ones(), Lanes::Ones(), Lanes::Ones()};
        Lanes r_min = Lanes::Ones();
        std::array<std::uint64_t, width> bit{};
    };
    std::array<Chunk, 64 / width> m_chunks;
    int m_count = 0;
};

// Unit-sphere coordinates of a block of points (rows contiguous: whole-row arithmetic) and
// one value per point.
using BlockPoints = Eigen::Matrix<Real, 3, Eigen::Dynamic, 0, 3, candidate_block>;
using BlockValues = Eigen::Array<Real, 1, Eigen::Dynamic, Eigen::RowMajor, 1, candidate_block>;

// Bounding box of points.
struct PointBounds {
    Vec3 low = Vec3::Constant(std::numeric_limits<Real>::infinity());
    Vec3 high = Vec3::Constant(-std::numeric_limits<Real>::infinity());
    template <class X>
    explicit PointBounds(const X& x) {
        for (Eigen::Index i = 0; i < x.cols(); ++i) {
            low = low.cwiseMin(x.col(i));
            high = high.cwiseMax(x.col(i));
        }
    }
    // Lower bound of the distance between a point inside and the ellipsoid `f`.
    [[nodiscard]] Real gap(const ListEllipsoid& f) const { return (f.low - high).cwiseMax(low - f.high).maxCoeff(); }
};

// Refreshes bit e of the lists of points x (any frame; `f` and `bounds` in the same frame):
// set where a point is within `margin` of the ellipsoid, cleared elsewhere. With `clearance`
// (one per point), stores each unlisted point's clearance from the ellipsoid, +inf for the
// listed ones.
// Bounds of the whole point set, then of each block of `candidate_block` points.
struct BlockBounds {
    PointBounds all;
    std::vector<PointBounds> blocks;
    explicit BlockBounds(const Matrix3X& x) : all(x) {
        for (Eigen::Index begin = 0; begin < x.cols(); begin += candidate_block)
            blocks.emplace_back(x.middleCols(begin, std::min<Eigen::Index>(candidate_block, x.cols() - begin)));
    }
};

std::uint64_t refresh_bit(const Matrix3X& x, const BlockBounds& bounds, const ListEllipsoid& f, std::size_t e,
                          Real margin, std::vector<std::uint64_t>& candidates, Real* clearance_out) {
    const Eigen::Index n = x.cols();
    const std::uint64_t bit = std::uint64_t(1) << e;
    std::uint64_t* out = candidates.data();
    Real* b = clearance_out;
    constexpr Real listed = std::numeric_limits<Real>::infinity();
    // Broad phase, whole garment then blocks: a gap between the boxes bounds every distance.
    if (const Real gap = bounds.all.gap(f); gap > margin) {
        for (Eigen::Index i = 0; i < n; ++i) out[i] &= ~bit;
        if (b)
            for (Eigen::Index i = 0; i < n; ++i) b[i] = gap - clearance_rounding_m;
        return 0;
    }
    std::uint64_t tests = 0;
    BlockPoints y;
    BlockValues clearance;
    for (Eigen::Index begin = 0; begin < n; begin += candidate_block) {
        const Eigen::Index count = std::min<Eigen::Index>(candidate_block, n - begin);
        const auto block = x.middleCols(begin, count);
        if (const Real gap = bounds.blocks[static_cast<std::size_t>(begin / candidate_block)].gap(f); gap > margin) {
            for (Eigen::Index i = begin; i < begin + count; ++i) out[i] &= ~bit;
            if (b)
                for (Eigen::Index i = begin; i < begin + count; ++i) b[i] = gap - clearance_rounding_m;
            continue;
        }
        y.noalias() = f.to_unit * block;
        y.colwise() -= f.offset;
        clearance = clearance_of(y, f.radii);
        for (Eigen::Index i = 0; i < count; ++i) out[begin + i] = clearance[i] <= margin ? out[begin + i] | bit : out[begin + i] & ~bit;
        if (b)
            for (Eigen::Index i = 0; i < count; ++i)
                b[begin + i] = clearance[i] <= margin ? listed : clearance[i] - clearance_rounding_m;
        tests += static_cast<std::uint64_t>(count);
    }
    return tests;
}

// Entry and exit distances of the ray o + t d (|d| = 1) through the ellipsoid; in > out if it misses.
inline std::pair<Real, Real> ray_span(const EllipsoidFrame& f, const Vec3& o, const Vec3& d) {
    const Eigen::Vector3d oo = to_unit_sphere(f, o).cast<double>();
    const Eigen::Vector3d dd = (f.to_unit * d).cast<double>();
    const double a = dd.squaredNorm(), b = 2 * oo.dot(dd), c = oo.squaredNorm() - 1;
    const double disc = b * b - 4 * a * c;
    if (disc < 0 || a <= 0) return {1, 0};
    const double root = std::sqrt(disc);
    return {static_cast<Real>((-b - root) / (2 * a)), static_cast<Real>((-b + root) / (2 * a))};
}

// Smallest t >= 0 at which o + t d is outside every ellipsoid of `set`. Each is convex, so the
// ray is inside it on one interval: step past every interval that covers t until none does
// (each interval is passed at most once). Stops early once t exceeds `give_up`.
inline Real first_point_outside(std::span<const EllipsoidFrame> frames, std::uint64_t set, const Vec3& o,
                                const Vec3& d, Real give_up) {
    Real t = 0;
    for (int pass = 0; pass <= 64 && t <= give_up; ++pass) {
        bool advanced = false;
        for_each_bit(set, [&](int e) {
            const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
            const auto [in, out] = ray_span(f, o, d);
            if (in <= t && t < out) {
                t = out + 2 * surface_clearance(f) * f.radii_m.maxCoeff();
                advanced = true;
            }
        });
        if (!advanced) break;
    }
    return t;
}

// Way out for a particle the re-test rounds could not free: from `x` (where it was detected),
// along the shortest of the outward normals and centre lines of the ellipsoids it was found
// in, their bisector and crease (the first two), the direction the rounds moved it and the
// direction back to where it started the substep, to the first point outside every active
// ellipsoid. Never carried past an ellipsoid it could stop before, unlike a single ray from a
// centre (which, through overlapping thigh and shin, ran out past the foot).
inline Vec3 fallback_exit(std::span<const EllipsoidFrame> frames, std::uint64_t active, const Vec3& x,
                          std::uint64_t hits, const Vec3& after_rounds, const Vec3& start) {
    std::array<Vec3, 10> ways;
    std::size_t count = 0;
    const auto add = [&](const Vec3& d) {
        const Real length = d.norm();
        if (length > Real(1e-9) && count < ways.size()) ways[count++] = d / length;
    };
    std::array<Vec3, 2> normals{Vec3::Zero(), Vec3::Zero()};
    std::size_t found = 0;
    for_each_bit(hits, [&](int e) {
        const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
        const Vec3 n = f.to_unit.transpose() * to_unit_sphere(f, x);
        if (found < normals.size()) normals[found++] = n.normalized();
        if (count + 2 <= 6) {
            add(n);
            add(x - f.center);
        }
    });
    if (found == 2) {
        add(normals[0] + normals[1]);
        add(normals[0].cross(normals[1]));
        add(normals[1].cross(normals[0]));
    }
    add(after_rounds - x);
    add(start - x);
    if (count == 0) ways[count++] = Vec3::UnitY();
    Real best = std::numeric_limits<Real>::infinity();
    Vec3 out = x;
    for (std::size_t k = 0; k < count; ++k) {
        const Real t = first_point_outside(frames, active, x, ways[k], best);
        if (t < best) {
            best = t;
            out = x + t * ways[k];
        }
    }
    return out;
}

}  // namespace

Real penetration_depth(const EllipsoidFrame& f, const Vec3& x) {
    const Real y_sq = to_unit_sphere(f, x).squaredNorm();
    if (y_sq >= 1) return 0;
    const Real y = std::sqrt(y_sq);
    if (y <= Real(1e-6)) return f.radii_m.minCoeff();
    return (x - f.center).norm() * (1 / y - 1);
}

void push_out(const EllipsoidFrame& f, const Vec3& y, Vec3& x, Vec3& v) {
    remove_approach(f, place_on_surface(f, y, x), x, v);
}

std::uint64_t active_mask(std::span<const EllipsoidFrame> frames) {
    std::uint64_t mask = 0;
    for (std::size_t e = 0; e < frames.size() && e < 64; ++e)
        if (frames[e].active) mask |= std::uint64_t(1) << e;
    return mask;
}

std::uint64_t refresh_candidate_bit(const Matrix3X& x, std::span<const EllipsoidFrame> frames, std::size_t e,
                                    Real margin, std::vector<std::uint64_t>& candidates) {
    candidates.resize(static_cast<std::size_t>(x.cols()), 0);
    if (e >= 64) return 0;
    if (e >= frames.size() || !frames[e].active) {
        for (std::uint64_t& c : candidates) c &= ~(std::uint64_t(1) << e);
        return 0;
    }
    return refresh_bit(x, BlockBounds(x), ListEllipsoid(frames[e]), e, margin, candidates, nullptr);
}

std::uint64_t build_candidate_lists(const Matrix3X& x, std::span<const EllipsoidFrame> frames, Real margin,
                                    std::vector<std::uint64_t>& candidates) {
    candidates.assign(static_cast<std::size_t>(x.cols()), 0);
    std::uint64_t tests = 0;
    for (std::size_t e = 0; e < frames.size() && e < 64; ++e) tests += refresh_candidate_bit(x, frames, e, margin, candidates);
    return tests;
}

CollisionResult collide_particles(Matrix3X& x, Matrix3X& v, const VectorX& inv_mass,
                                  std::span<const EllipsoidFrame> frames, const std::vector<std::uint64_t>* candidates,
                                  std::vector<std::uint64_t>& last_collided, DetectedPairs* detected,
                                  const Matrix3X* x_start, Real h, std::span<const Real> list_slack) {
    CollisionResult r;
    const Eigen::Index n = x.cols();
    last_collided.resize(static_cast<std::size_t>(n), 0);
    if (detected) detected->assign(static_cast<std::size_t>(n), 0);
    const std::uint64_t active = active_mask(frames);
    const bool whole_move = x_start != nullptr && h > 0;

    LaneBits block_lists{}, block_hits{};
    for (Eigen::Index p = 0; p < n; ++p) {
        const std::size_t pi = static_cast<std::size_t>(p);
        if (candidates && p % detect_lanes == 0) {
            // List mode: the lists of the next block of particles at once (detect_block).
            const Eigen::Index count = std::min(detect_lanes, n - p);
            block_lists.fill(0);
            for (Eigen::Index l = 0; l < count; ++l)
                if (inv_mass[p + l] != 0) block_lists[static_cast<std::size_t>(l)] = (*candidates)[pi + static_cast<std::size_t>(l)] & active;
            detect_block(x, p, count, frames, block_lists, block_hits);
            for (Eigen::Index l = 0; l < count; ++l) {  // the particles without a hit are done
                const std::size_t li = static_cast<std::size_t>(l);
                r.tests += static_cast<std::uint64_t>(std::popcount(block_lists[li]));
                if (block_hits[li] != 0) continue;
                last_collided[pi + li] = 0;
                if (detected) (*detected)[pi + li] = 0;
            }
        }
        if (candidates && block_hits[static_cast<std::size_t>(p % detect_lanes)] == 0) continue;
        if (inv_mass[p] == 0) {
            last_collided[pi] = 0;
            continue;
        }
        const std::uint64_t list = (candidates ? (*candidates)[pi] : ~std::uint64_t(0)) & active;
        const std::uint64_t last = last_collided[pi] & list;
        Vec3 xp = x.col(p);
        std::uint64_t hits = 0;
        if (candidates) {
            hits = block_hits[static_cast<std::size_t>(p % detect_lanes)];
        } else {
            for_each_bit(list, [&](int e) {
                ++r.tests;
                if (to_unit_sphere(frames[static_cast<std::size_t>(e)], xp).squaredNorm() < 1) hits |= std::uint64_t(1) << e;
            });
        }
        for_each_bit(hits, [&](int e) {
            const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
            const Real y_len = to_unit_sphere(f, xp).norm();
            const Real depth = y_len > Real(1e-6) ? (xp - f.center).norm() * (1 / y_len - 1) : f.radii_m.minCoeff();
            r.max_penetration_m = std::max(r.max_penetration_m, depth);
        });
        if (detected) (*detected)[pi] = hits;
        last_collided[pi] = hits;
        if (hits == 0) continue;

        Vec3 vp = v.col(p);
        const Vec3 x_detected = xp;
        auto respond = [&](int e) {
            const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
            const Vec3 y = to_unit_sphere(f, xp);
            if (y.squaredNorm() >= 1) return false;
            const Vec3 y_surface = place_shortest(f, y, xp);
            if (!whole_move) remove_approach(f, y_surface, xp, vp);  // else from the whole move, below
            ++r.collisions;
            return true;
        };
        for_each_bit(hits & last, respond);
        for_each_bit(hits & ~last, respond);
        // Pushed beyond what the list still covers: every ellipsoid may now be near.
        const Real slack = list_slack.size() == static_cast<std::size_t>(n) ? list_slack[pi] : std::numeric_limits<Real>::infinity();
        const Real slack_sq = slack * slack;
        std::uint64_t retest = (xp - x_detected).squaredNorm() > slack_sq ? active : list;
        if (std::popcount(retest) > 1 || retest != list) {
            bool moved = true;
            for (int round = 0; round < max_retest_rounds && moved; ++round) {
                moved = false;
                if ((xp - x_detected).squaredNorm() > slack_sq) retest = active;
                // A single contact leaves its ellipsoid outside by construction (place_on_surface):
                // the first round tests only the others.
                const std::uint64_t left = round == 0 && std::popcount(hits) == 1 ? hits : 0;
                for_each_bit(retest & ~left, [&](int e) {
                    ++r.tests;
                    moved = respond(e) || moved;
                });
            }
            if (moved) {
                // Still between overlapping ellipsoids (a crease, the thighs where they meet):
                // leave from where it was detected by the shortest of a few straight ways out,
                // past every ellipsoid the way crosses (fallback_exit).
                xp = fallback_exit(frames, active, x_detected, hits, xp,
                                   x_start != nullptr ? Vec3(x_start->col(p)) : x_detected);
                Real depth = 0;
                for_each_bit(active, [&](int e) {
                    ++r.tests;
                    depth = std::max(depth, penetration_depth(frames[static_cast<std::size_t>(e)], xp));
                });
                if (depth > Real(1e-5)) ++r.unresolved;
            }
        }
        if (whole_move) {
            // Velocity of the whole move, then no normal velocity relative to any surface touched.
            vp = (xp - x_start->col(p)) / h;
            for_each_bit(last_collided[pi], [&](int e) {
                const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
                const Vec3 normal = (f.to_unit.transpose() * to_unit_sphere(f, xp)).normalized();
                const Vec3 surface_velocity = body_velocity_at(f, xp);
                vp -= (vp - surface_velocity).dot(normal) * normal;
            });
        }
        x.col(p) = xp;
        v.col(p) = vp;
    }
    return r;
}

DetectedPairs detect_brute_force(const Matrix3X& x, const VectorX& inv_mass, std::span<const EllipsoidFrame> frames) {
    const Eigen::Index n = x.cols();
    DetectedPairs out(static_cast<std::size_t>(n), 0);
    const std::uint64_t active = active_mask(frames);
    LaneBits tested{}, hits{};
    for (Eigen::Index begin = 0; begin < n; begin += detect_lanes) {
        const Eigen::Index count = std::min(detect_lanes, n - begin);
        tested.fill(0);
        for (Eigen::Index l = 0; l < count; ++l)
            if (inv_mass[begin + l] != 0) tested[static_cast<std::size_t>(l)] = active;
        detect_block(x, begin, count, frames, tested, hits);
        for (Eigen::Index l = 0; l < count; ++l) out[static_cast<std::size_t>(begin + l)] = hits[static_cast<std::size_t>(l)];
    }
    return out;
}

namespace {

// A collider in the anchor's frame (rigid, so distances hold), as a frame for the list tests.
EllipsoidFrame in_anchor_frame(const EllipsoidFrame& f, const Affine3& anchor) {
    EllipsoidFrame a;
    a.rotation = anchor.linear().transpose() * f.rotation;
    a.center = anchor.linear().transpose() * (f.center - anchor.translation());
    a.radii_m = f.radii_m;
    a.to_unit = f.to_unit * anchor.linear();
    a.active = f.active;
    return a;
}

// How far any point of the ellipsoid `then` can be from its image in `now`: |dc| + |dL|_F
// (|dL u| <= |dL|_F for |u| <= 1).
Real ellipsoid_move(const Affine3& now, const Affine3& then) {
    return (now.translation() - then.translation()).norm() + (now.linear() - then.linear()).norm();
}

// An inactive collider's reference is a zero map.
bool has_reference(const Affine3& t) { return t.linear().squaredNorm() > 0; }

}  // namespace

void update_candidate_lists(Garment& g) {
    const Eigen::Index n = g.x.cols();
    const std::size_t e_count = std::min<std::size_t>(g.frames.size(), 64);
    const Affine3 anchor = anchor_frame(g);
    const Mat3 to_anchor = anchor.linear().transpose();  // rigid: inverse = transpose
    const Real margin = g.material.candidate_margin_m;
    auto& clearance = g.list_clearance_m;  // particle x ellipsoid, column e contiguous
    VectorX& slack = g.list_slack_m;
    std::uint64_t tests = 0;

    // 1. Each particle's position and move d_p in the anchor frame (whole arrays).
    Matrix3X& local = g.list_scratch;
    local.resize(3, n);
    local.noalias() = to_anchor * g.x;
    local.colwise() -= to_anchor * anchor.translation();
    const bool valid = g.lists_valid && g.list_anchor_frames.size() == e_count && g.list_anchor_x.cols() == n &&
                       clearance.rows() == n && clearance.cols() == static_cast<Eigen::Index>(e_count) &&
                       g.candidates.size() == static_cast<std::size_t>(n);
    if (!valid) {  // everything from scratch: every particle and every ellipsoid is its own reference
        g.candidates.assign(static_cast<std::size_t>(n), 0);
        g.list_anchor_x = local;
        g.list_anchor_frames.assign(e_count, Affine3(Eigen::Matrix<Real, 4, 4>::Zero()));
        clearance.setConstant(n, static_cast<Eigen::Index>(e_count), std::numeric_limits<Real>::infinity());
        ++g.counters.list_rebuilds;
    }
    slack.resize(n);
    slack = (local - g.list_anchor_x).colwise().norm().transpose();

    // 2. Ellipsoids: refresh bit e against the particles' reference points when e has moved
    //    its share since its reference pose, which it then becomes. D_e: its move since.
    std::optional<BlockBounds> bounds;  // of the reference points, on first use
    const Real ellipsoid_limit = ellipsoid_refresh_share * margin;
    std::array<Real, 64> moved_since{};
    for (std::size_t e = 0; e < e_count; ++e) {
        Affine3& then = g.list_anchor_frames[e];
        if (!g.frames[e].active) {
            if (has_reference(then)) {
                tests += refresh_candidate_bit(g.list_anchor_x, g.frames, e, margin, g.candidates);  // clears it
                clearance.col(static_cast<Eigen::Index>(e)).setConstant(std::numeric_limits<Real>::infinity());
                then.matrix().setZero();
            }
            continue;
        }
        const EllipsoidFrame current = in_anchor_frame(g.frames[e], anchor);
        const Affine3 now = unit_to_world(current);
        const Real moved = has_reference(then) ? ellipsoid_move(now, then) : std::numeric_limits<Real>::infinity();
        if (moved <= ellipsoid_limit) {
            moved_since[e] = moved;
            continue;
        }
        if (!bounds) bounds.emplace(g.list_anchor_x);
        tests += refresh_bit(g.list_anchor_x, *bounds, ListEllipsoid(current), e, margin, g.candidates,
                             clearance.col(static_cast<Eigen::Index>(e)).data());
        then = now;
    }

    // 3. Particles: a list is exact while d_p + D_e < C_pe for every unlisted e, the
    //    clearance between their references: the slack is min_e (C_pe - D_e) - d_p, whole
    //    columns. A particle without slack becomes its own reference and is tested against
    //    every reference ellipsoid.
    const std::uint64_t active = active_mask(g.frames);
    VectorX room = VectorX::Constant(n, std::numeric_limits<Real>::infinity());
    for_each_bit(active, [&](int e) {
        const Real* c = clearance.col(e).data();
        const Real moved = moved_since[static_cast<std::size_t>(e)];
        Real* r = room.data();
        for (Eigen::Index p = 0; p < n; ++p) r[p] = std::min(r[p], c[p] - moved);
    });
    slack = room - slack;
    EllipsoidLanes references;  // filled on first use
    std::array<Real, 64> particle_clearance{};
    for (Eigen::Index p = 0; p < n; ++p) {
        if (slack[p] >= 0 || g.inv_mass[p] == 0) continue;  // pinned: never tested (method §3.5)
        if (references.empty()) {
            for_each_bit(active, [&](int e) {
                references.add(ListEllipsoid(make_ellipsoid_frame(g.list_anchor_frames[static_cast<std::size_t>(e)])), e);
            });
        }
        g.list_anchor_x.col(p) = local.col(p);
        std::uint64_t bits = 0;
        references.test(local.col(p), margin, bits, particle_clearance);
        g.candidates[static_cast<std::size_t>(p)] = bits;
        Real left = std::numeric_limits<Real>::infinity();
        for_each_bit(active, [&](int e) {
            const std::size_t ei = static_cast<std::size_t>(e);
            clearance(p, e) = particle_clearance[ei] - clearance_rounding_m;
            left = std::min(left, clearance(p, e) - moved_since[ei]);
        });
        slack[p] = std::max(Real(0), left);
        tests += static_cast<std::uint64_t>(std::popcount(active));
    }
    g.lists_valid = true;
    g.counters.list_rebuild_tests += tests;
    g.counters.frame_list_rebuild_tests += tests;
}

CollisionResult collide_garment(Garment& g, DetectedPairs* detected, Real h) {
    const Eigen::Index n = g.x.cols();
    const std::vector<std::uint64_t>* lists = nullptr;
    std::span<const Real> slack;
    if (g.collision == CollisionMode::candidate_lists) {
        update_candidate_lists(g);
        lists = &g.candidates;
        slack = std::span<const Real>(g.list_slack_m.data(), static_cast<std::size_t>(g.list_slack_m.size()));
    }
    const bool have_start = h > 0 && g.x_start.cols() == n;
    const CollisionResult r = collide_particles(g.x, g.v, g.inv_mass, g.frames, lists, g.last_collided, detected,
                                                have_start ? &g.x_start : nullptr, h, slack);
    g.counters.frame_collision_tests += r.tests;
    g.counters.collision_tests += r.tests;
    g.counters.frame_collisions += r.collisions;
    g.counters.collisions += r.collisions;
    g.counters.max_penetration_m = std::max(g.counters.max_penetration_m, r.max_penetration_m);
    return r;
}

}  // namespace drape
