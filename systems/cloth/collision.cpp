// Particle-ellipsoid collision (method §5); step order in collision.hpp.
#include "drape/systems/cloth/collision.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "drape/components/ground_plane.hpp"
#include "drape/systems/cloth/body.hpp"

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
// leaves along the longest axis. Returns the unit-sphere image of the new place. `outside`:
// 1 + surface_clearance(f).
inline Vec3 place_on_surface(const EllipsoidFrame& f, const Vec3& y_in, Vec3& x, Real outside) {
    Vec3 y = y_in;
    Real length = y.norm();
    if (length <= Real(1e-6)) {
        Eigen::Index axis = 0;
        f.radii_m.maxCoeff(&axis);
        y = Vec3::Unit(axis);
        length = 1;
    }
    const Vec3 y_surface = y * (outside / length);
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
// `y` = to_unit (x - c) with y_sq = |y|^2 < 1, inv_len = 1 / |y|; `along_centre` = the
// centre-line push-out (centre_line_depth).
inline Vec3 place_shortest(const EllipsoidFrame& f, const Vec3& y, Real y_sq, Real inv_len, Real along_centre, Vec3& x,
                           Real outside) {
    if (y_sq > Real(1e-12)) {
        if (along_centre > shallow_share * f.radii_m.minCoeff()) {
            // Along the normal n = L^T y (L = to_unit): the unit-sphere image moves along d = L n,
            // |y + s d| = 1 at s = -2c / (b + sqrt(b^2 - 4ac)) with a = |d|^2, b = 2 y.d = 2 |n|^2,
            // c = |y|^2 - 1 < 0 (the form without cancellation); the world move is s |n|.
            const Vec3 n = f.to_unit.transpose() * y;
            const Vec3 d = f.to_unit * n;
            const Real a = d.squaredNorm(), b = 2 * n.squaredNorm(), c = y_sq - 1;
            const Real s = -2 * c / (b + std::sqrt(b * b - 4 * a * c));
            if (s * n.norm() < along_centre) return place_on_surface(f, y + s * d, x, outside);
        }
        // Along the centre line: x - c = R diag(r) y scales with y.
        const Real scale = outside * inv_len;
        x = f.center + (x - f.center) * scale;
        return y * scale;
    }
    return place_on_surface(f, y, x, outside);
}

// How far the centre-line response moves a point inside: offset d = x - c, |y| = y_len < 1,
// inv_len = 1 / y_len.
inline Real centre_line_depth(const EllipsoidFrame& f, const Vec3& d, Real y_len, Real inv_len) {
    return y_len > Real(1e-6) ? d.norm() * (inv_len - 1) : f.radii_m.minCoeff();
}

// Outward unit normal at the point with unit-sphere image y (not the centre): L^T y, normalised.
inline Vec3 surface_normal(const EllipsoidFrame& f, const Vec3& y) {
    const Vec3 g = f.to_unit.transpose() * y;
    const Real length_sq = g.squaredNorm();
    return length_sq > 0 ? Vec3(g * (1 / std::sqrt(length_sq))) : g;
}

// Inelastic contact (method §5): no velocity into the surface, relative to its motion.
inline void remove_approach(const EllipsoidFrame& f, const Vec3& y_surface, const Vec3& x, Vec3& v) {
    const Vec3 normal = surface_normal(f, y_surface);
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

// ---- Detection (method §5): the unit-sphere test, 64 consecutive particles at a time.

constexpr Eigen::Index detect_lanes = 64;
using DetectLanes = Eigen::Array<Real, detect_lanes, 1>;
using LaneBits = std::array<std::uint64_t, detect_lanes>;

// Bit e of hits[l] is set when ellipsoid e is in tested[l] and contains particle begin + l
// (|y| < 1). Every ellipsoid in any of the lists is tested against the whole block in one
// pass of vector instructions; lanes whose list leaves it out are discarded. Brute force's
// reference detection uses the same arithmetic, so both agree to the bit.
inline bool detect_block(const Matrix3X& x, Eigen::Index begin, Eigen::Index count,
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
    bool found = false;  // some lane inside some ellipsoid (a lane outside its list may be one)
    for_each_bit(any, [&](int e) {
        const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
        const Mat3& m = f.to_unit;
        const DetectLanes d0 = p0 - f.center[0], d1 = p1 - f.center[1], d2 = p2 - f.center[2];
        const DetectLanes y0 = m(0, 0) * d0 + m(0, 1) * d1 + m(0, 2) * d2;
        const DetectLanes y1 = m(1, 0) * d0 + m(1, 1) * d1 + m(1, 2) * d2;
        const DetectLanes y2 = m(2, 0) * d0 + m(2, 1) * d1 + m(2, 2) * d2;
        const DetectLanes y_sq = y0 * y0 + y1 * y1 + y2 * y2;
        if (y_sq.minCoeff() >= 1) return;  // the common case: no lane inside
        found = true;
        const std::uint64_t bit = std::uint64_t(1) << e;
        for (std::size_t l = 0; l < static_cast<std::size_t>(detect_lanes); ++l)
            hits[l] |= y_sq[static_cast<Eigen::Index>(l)] < 1 ? tested[l] & bit : 0;
    });
    return found;
}

// detect_block for one particle p (a particle collided on its own), without the vector
// lanes: the same test, each ellipsoid of `tested` in turn.
inline bool detect_one(const Matrix3X& x, Eigen::Index p, std::span<const EllipsoidFrame> frames, std::uint64_t tested,
                       std::uint64_t& hits) {
    hits = 0;
    for_each_bit(tested, [&](int e) {
        const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
        if ((f.to_unit * (x.col(p) - f.center)).squaredNorm() < 1) hits |= std::uint64_t(1) << e;
    });
    return hits != 0;
}

// ---- Candidate lists (method §5, spatial locality); see collision.hpp step 1.

// An ellipsoid's bit is refreshed in every list once the ellipsoid has moved this share of
// the margin since its reference pose; a particle's list is refreshed when its own move
// plus that of an unlisted ellipsoid reaches the clearance between their references. docs/cloth.md has the measurements.
constexpr Real ellipsoid_refresh_share = Real(0.5);
// Particles per block in a bit refresh; a block whose bounding box is farther than the
// margin from the ellipsoid's box is cleared without a test.
constexpr Eigen::Index candidate_block = 64;
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

// Lower bound of the distance from a point to an ellipsoid, from its unit-sphere
// coordinates y: the unit-sphere map stretches distances by at most 1 / r_min, and the
// ellipsoid lies inside its box of half sizes r_i in its own axes. Negative inside.
inline Real clearance_of(Real y0, Real y1, Real y2, Real r0, Real r1, Real r2, Real r_min) {
    const Real box = std::max(std::max(r0 * (std::abs(y0) - 1), r1 * (std::abs(y1) - 1)), r2 * (std::abs(y2) - 1));
    return std::max(r_min * (std::sqrt(y0 * y0 + y1 * y1 + y2 * y2) - 1), box);
}

// ---- Give (EllipsoidCollider::give_m): how deep a point may lie inside giving ellipsoid
// `f`, its give less the point's distance outside the nearest ellipsoid of `holds` (those
// that do not give; a lower bound of the distance, clearance_of): the whole give on their
// surface, none a give away from them. Cloth caught between a forearm and the hips then
// keeps to the hips, inside the forearm's bulge, instead of being squeezed out of both.
inline Real give_allowance(std::span<const EllipsoidFrame> frames, std::uint64_t holds, const EllipsoidFrame& f, const Vec3& x) {
    Real gap = std::numeric_limits<Real>::infinity();
    for_each_bit(holds, [&](int h) {
        const EllipsoidFrame& t = frames[static_cast<std::size_t>(h)];
        const Vec3 y = t.to_unit * (x - t.center);
        gap = std::min(gap, clearance_of(y[0], y[1], y[2], t.radii_m[0], t.radii_m[1], t.radii_m[2], t.radii_m.minCoeff()));
    });
    return f.give_m - std::clamp(gap, Real(0), f.give_m);
}

// A point within this of its allowance counts as outside: a push onto the allowance moves
// the point and with it the allowance, and the re-test rounds would chase it.
constexpr Real give_tolerance_m = Real(1e-4);

// The masks of the active frames that give and of those that hold.
inline std::pair<std::uint64_t, std::uint64_t> give_masks(std::span<const EllipsoidFrame> frames, std::uint64_t active) {
    std::uint64_t gives = 0;
    for_each_bit(active, [&](int e) {
        if (frames[static_cast<std::size_t>(e)].give_m > 0) gives |= std::uint64_t(1) << e;
    });
    return {gives, active & ~gives};
}

// The reference ellipsoids of a list update as structure of arrays, lane e = ellipsoid e,
// so that one point is tested against all of them in a few vector instructions (a
// particle's whole list refresh). A lane without an active ellipsoid holds one 1e18 m away
// and reports +inf.
class ReferenceLanes {
public:
    static constexpr std::size_t max_lanes = 64;

    explicit ReferenceLanes(std::size_t count)
        : m_lanes(static_cast<int>(std::min<std::size_t>((count + 15) / 16 * 16, max_lanes))) {
        const auto lanes = static_cast<std::size_t>(m_lanes);  // the lanes used, not all of max_lanes
        for (auto& a : m_to_unit) std::fill_n(a.begin(), lanes, Real(0));
        for (auto& a : m_offset) std::fill_n(a.begin(), lanes, Real(0));
        for (auto& a : m_radii) std::fill_n(a.begin(), lanes, Real(1));
        std::fill_n(m_offset[0].begin(), lanes, Real(-1e18));
        std::fill_n(m_r_min.begin(), lanes, Real(1));
        std::fill_n(m_moved.begin(), lanes, Real(0));
        std::fill_n(m_inactive.begin(), lanes, infinity);
    }

    // Ellipsoid e as the reference, its unit sphere -> reference frame map `t` = [R diag(r) | c]
    // (so its unit-sphere map is diag(1/r^2) L^T (x - c), L = R diag(r)), moved `moved` since (D_e).
    void set(std::size_t e, const Affine3& t, Real moved) {
        const Mat3 l = t.linear();
        const Vec3 radii = l.colwise().norm().transpose();
        const Mat3 to_unit = radii.cwiseAbs2().cwiseInverse().asDiagonal() * l.transpose();
        const Vec3 offset = to_unit * t.translation();
        for (std::size_t i = 0; i < 9; ++i) m_to_unit[i][e] = to_unit(static_cast<Eigen::Index>(i / 3), static_cast<Eigen::Index>(i % 3));
        for (std::size_t i = 0; i < 3; ++i) {
            m_offset[i][e] = offset[static_cast<Eigen::Index>(i)];
            m_radii[i][e] = radii[static_cast<Eigen::Index>(i)];
        }
        m_r_min[e] = radii.minCoeff();
        m_moved[e] = moved;
        m_inactive[e] = 0;
    }

    // Lists the ellipsoids within `margin` of x (the returned bits), leaves in `stored[e]`
    // each one's clearance (clearance_of) less the rounding allowance, +inf where listed or
    // inactive, and returns min_e (stored[e] - D_e).
    std::uint64_t test(const Vec3& x, Real margin, std::array<Real, max_lanes>& stored, Real& left) const {
        const Real p0 = x[0], p1 = x[1], p2 = x[2];
        for (int l = 0; l < m_lanes; ++l) {  // vectorised: one lane per ellipsoid
            const auto& m = m_to_unit;
            const Real y0 = m[0][l] * p0 + m[1][l] * p1 + m[2][l] * p2 - m_offset[0][l];
            const Real y1 = m[3][l] * p0 + m[4][l] * p1 + m[5][l] * p2 - m_offset[1][l];
            const Real y2 = m[6][l] * p0 + m[7][l] * p1 + m[8][l] * p2 - m_offset[2][l];
            const Real d = clearance_of(y0, y1, y2, m_radii[0][l], m_radii[1][l], m_radii[2][l], m_r_min[l]);
            stored[static_cast<std::size_t>(l)] = (d <= margin ? infinity : d - clearance_rounding_m) + m_inactive[l];
        }
        using Lanes = Eigen::Map<const Eigen::Array<Real, 16, 1>, Eigen::Aligned64>;  // register-wide reductions
        left = infinity;
        for (int k = 0; k < m_lanes; k += 16) left = std::min(left, (Lanes(stored.data() + k) - Lanes(m_moved.data() + k)).minCoeff());
        std::uint64_t bits = 0;
        for (int l = 0; l < m_lanes; ++l)  // an OR reduction of vector lanes
            bits |= stored[static_cast<std::size_t>(l)] == infinity && m_inactive[l] == 0 ? lane_bit[static_cast<std::size_t>(l)] : 0;
        return bits;
    }

private:
    static constexpr Real infinity = std::numeric_limits<Real>::infinity();
    static constexpr std::array<std::uint64_t, max_lanes> lane_bit = [] {
        std::array<std::uint64_t, max_lanes> bits{};
        for (std::size_t l = 0; l < max_lanes; ++l) bits[l] = std::uint64_t(1) << l;
        return bits;
    }();
    using Row = std::array<Real, max_lanes>;
    int m_lanes;
    alignas(64) std::array<Row, 9> m_to_unit;
    alignas(64) std::array<Row, 3> m_offset;
    alignas(64) std::array<Row, 3> m_radii;
    alignas(64) Row m_r_min;
    alignas(64) Row m_moved;
    alignas(64) Row m_inactive;  ///< 0 for a lane with an ellipsoid, else +inf.
};

// Bounding box of points.
struct PointBounds {
    Vec3 low = Vec3::Constant(std::numeric_limits<Real>::infinity());
    Vec3 high = Vec3::Constant(-std::numeric_limits<Real>::infinity());
    PointBounds() = default;
    // Of points [begin, begin + count) of x: whole rows at once.
    PointBounds(const Matrix3XRows& x, Eigen::Index begin, Eigen::Index count) {
        for (int i = 0; i < 3; ++i) {
            const Real* row = x.row(i).data() + begin;
            if (count == candidate_block) {  // fixed size: register-wide reductions
                const Eigen::Map<const Eigen::Array<Real, candidate_block, 1>> block(row);
                low[i] = block.minCoeff();
                high[i] = block.maxCoeff();
            } else {
                for (Eigen::Index k = 0; k < count; ++k) {
                    low[i] = std::min(low[i], row[k]);
                    high[i] = std::max(high[i], row[k]);
                }
            }
        }
    }
    void add(const PointBounds& o) {
        low = low.cwiseMin(o.low);
        high = high.cwiseMax(o.high);
    }
    // Lower bound of the distance between a point inside and the ellipsoid `f`.
    [[nodiscard]] Real gap(const ListEllipsoid& f) const { return (f.low - high).cwiseMax(low - f.high).maxCoeff(); }
};

// Bounds of points [first, end) of x, and of each block of `candidate_block` points from first.
struct BlockBounds {
    PointBounds all;
    std::vector<PointBounds> blocks;
    BlockBounds(const Matrix3XRows& x, Eigen::Index first, Eigen::Index end) {
        blocks.reserve(static_cast<std::size_t>((end - first + candidate_block - 1) / candidate_block));
        for (Eigen::Index begin = first; begin < end; begin += candidate_block) {
            blocks.emplace_back(x, begin, std::min<Eigen::Index>(candidate_block, end - begin));
            all.add(blocks.back());
        }
    }
};

// Refreshes bit e of the lists of points [first, end) of x (any frame; `f` and `bounds`, of
// the same points, in the same frame): set where a point is within `margin` of the
// ellipsoid, cleared elsewhere, and stores in `clearance` (one per point of x) each unlisted
// point's clearance from the ellipsoid, +inf for the listed ones. Returns the tests done.
std::uint64_t refresh_bit(const Matrix3XRows& x, Eigen::Index first, Eigen::Index n, const BlockBounds& bounds,
                          const ListEllipsoid& f, std::size_t e, Real margin, std::vector<std::uint64_t>& candidates,
                          Real* clearance) {
    const std::uint64_t bit = std::uint64_t(1) << e;
    std::uint64_t* out = candidates.data();
    constexpr Real listed = std::numeric_limits<Real>::infinity();
    // Broad phase, all the points then blocks: a gap between the boxes bounds every distance.
    if (const Real gap = bounds.all.gap(f); gap > margin) {
        for (Eigen::Index i = first; i < n; ++i) out[i] &= ~bit;
        std::fill(clearance + first, clearance + n, gap - clearance_rounding_m);
        return 0;
    }
    const Real* x0 = x.row(0).data();
    const Real* x1 = x.row(1).data();
    const Real* x2 = x.row(2).data();
    const Mat3& m = f.to_unit;
    const Real r0 = f.radii[0], r1 = f.radii[1], r2 = f.radii[2], r_min = f.radii.minCoeff();
    std::uint64_t tests = 0;
    for (Eigen::Index begin = first; begin < n; begin += candidate_block) {
        const Eigen::Index end = std::min<Eigen::Index>(begin + candidate_block, n);
        if (const Real gap = bounds.blocks[static_cast<std::size_t>((begin - first) / candidate_block)].gap(f); gap > margin) {
            for (Eigen::Index i = begin; i < end; ++i) out[i] &= ~bit;
            std::fill(clearance + begin, clearance + end, gap - clearance_rounding_m);
            continue;
        }
        for (Eigen::Index i = begin; i < end; ++i) {  // vectorised: one lane per point
            const Real y0 = m(0, 0) * x0[i] + m(0, 1) * x1[i] + m(0, 2) * x2[i] - f.offset[0];
            const Real y1 = m(1, 0) * x0[i] + m(1, 1) * x1[i] + m(1, 2) * x2[i] - f.offset[1];
            const Real y2 = m(2, 0) * x0[i] + m(2, 1) * x1[i] + m(2, 2) * x2[i] - f.offset[2];
            const Real d = clearance_of(y0, y1, y2, r0, r1, r2, r_min);
            const bool near = d <= margin;
            out[i] = near ? out[i] | bit : out[i] & ~bit;
            clearance[i] = near ? listed : d - clearance_rounding_m;
        }
        tests += static_cast<std::uint64_t>(end - begin);
    }
    return tests;
}

}  // namespace

// Entry and exit distances of the ray o + t d (|d| = 1) through the ellipsoid; in > out if it misses.
std::pair<Real, Real> ray_span(const EllipsoidFrame& f, const Vec3& o, const Vec3& d) {
    const Eigen::Vector3d oo = to_unit_sphere(f, o).cast<double>();
    const Eigen::Vector3d dd = (f.to_unit * d).cast<double>();
    const double a = dd.squaredNorm(), b = 2 * oo.dot(dd), c = oo.squaredNorm() - 1;
    const double disc = b * b - 4 * a * c;
    if (disc < 0 || a <= 0) return {1, 0};
    const double root = std::sqrt(disc);
    return {static_cast<Real>((-b - root) / (2 * a)), static_cast<Real>((-b + root) / (2 * a))};
}

// Each ellipsoid is convex, so the ray is inside it on one interval: step past every interval
// that covers t until none does (each interval is passed at most once).
Real first_point_outside(std::span<const EllipsoidFrame> frames, std::uint64_t set, const Vec3& o, const Vec3& d,
                         Real give_up) {
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

namespace {

// Way out for a particle the re-test rounds could not free: from `x` (where it was detected),
// along the shortest of the outward normals and centre lines of the ellipsoids it was found
// in, their bisector and crease (the first two), the direction the rounds moved it and the
// direction toward `toward` (the particle above it on its warp line: the cloth it hangs
// from, which lies outside when the particle is caught in a crease the body closed on it),
// to the first point outside every active ellipsoid. Never carried past an ellipsoid it could
// stop before, unlike a single ray from a centre (which, through overlapping thigh and shin,
// ran out past the foot). Without the way toward the cloth, a particle caught between hip
// and thigh on Male_Casual (tight legs) left through the thigh, 33 cm from its neighbour.
inline Vec3 fallback_exit(std::span<const EllipsoidFrame> frames, std::uint64_t active, const Vec3& x,
                          std::uint64_t hits, const Vec3& after_rounds, const Vec3& toward) {
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
    add(toward - x);
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

Real depth_past_give(std::span<const EllipsoidFrame> frames, std::size_t e, const Vec3& x) {
    const EllipsoidFrame& f = frames[e];
    const Real depth = penetration_depth(f, x);
    if (depth <= 0 || f.give_m <= 0) return depth;
    const auto [gives, holds] = give_masks(frames, active_mask(frames));
    return std::max(Real(0), depth - give_allowance(frames, holds, f, x));
}

Real penetration_depth(const EllipsoidFrame& f, const Vec3& x) {
    const Vec3 d = x - f.center;
    const Real y_sq = (f.to_unit * d).squaredNorm();
    if (y_sq >= 1) return 0;
    const Real y_len = std::sqrt(y_sq);
    return centre_line_depth(f, d, y_len, 1 / y_len);
}

Vec3 leave_ellipsoid(const EllipsoidFrame& f, const Vec3& x) {
    Vec3 out = x;
    const Vec3 d = x - f.center;
    const Vec3 y = f.to_unit * d;
    const Real y_sq = y.squaredNorm();
    if (y_sq >= 1) return out;
    const Real y_len = std::sqrt(y_sq);
    const Real inv_len = y_len > 0 ? 1 / y_len : 0;
    place_shortest(f, y, y_sq, inv_len, centre_line_depth(f, d, y_len, inv_len), out, 1 + surface_clearance(f));
    return out;
}

void push_out(const EllipsoidFrame& f, const Vec3& y, Vec3& x, Vec3& v) {
    remove_approach(f, place_on_surface(f, y, x, 1 + surface_clearance(f)), x, v);
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
    const Matrix3XRows rows = x;
    VectorX clearance(x.cols());
    return refresh_bit(rows, 0, rows.cols(), BlockBounds(rows, 0, rows.cols()), ListEllipsoid(frames[e]), e, margin,
                       candidates, clearance.data());
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
                                  std::vector<std::uint64_t>& last_collided, DetectedPairs* detected, Real friction,
                                  std::span<const Real> list_slack, Eigen::Index first, Eigen::Index last_particle,
                                  bool respond_velocity, std::span<const std::uint32_t> above,
                                  std::span<const std::uint32_t> listed) {
    CollisionResult r;
    const Eigen::Index n = x.cols();
    const Eigen::Index end = last_particle < 0 ? n : std::min(last_particle, n);
    last_collided.resize(static_cast<std::size_t>(n), 0);
    if (detected) detected->assign(static_cast<std::size_t>(n), 0);
    const std::uint64_t active = active_mask(frames);
    std::array<Real, 64> outside{};  // per ellipsoid: 1 + surface_clearance, once per pass
    for_each_bit(active, [&](int e) { outside[static_cast<std::size_t>(e)] = 1 + surface_clearance(frames[static_cast<std::size_t>(e)]); });
    const auto [gives, holds] = give_masks(frames, active);
    // How deep the particle at `xp` may lie inside ellipsoid e (0 unless e gives).
    const auto allowance = [&](int e, const Vec3& xp) {
        return (gives >> e & 1) != 0 ? give_allowance(frames, holds, frames[static_cast<std::size_t>(e)], xp) : Real(0);
    };

    // Response for one particle and the ellipsoids `hits` (not empty) found to contain it.
    auto collide_one = [&](Eigen::Index p, std::uint64_t hits) {
        const std::size_t pi = static_cast<std::size_t>(p);
        const std::uint64_t list = (candidates ? (*candidates)[pi] : ~std::uint64_t(0)) & active;
        const std::uint64_t last = last_collided[pi] & list;
        Vec3 xp = x.col(p);
        // The first contact answered is measured on the way (below); any other at the detected place.
        const int first = std::countr_zero((hits & last) != 0 ? hits & last : hits);
        for_each_bit(hits & ~(std::uint64_t(1) << first), [&](int e) {
            r.max_penetration_m = std::max(r.max_penetration_m, penetration_depth(frames[static_cast<std::size_t>(e)], xp) - allowance(e, xp));
        });
        if (detected) (*detected)[pi] = hits;
        last_collided[pi] = hits;

        Vec3 vp = v.col(p);
        const Vec3 x_detected = xp;
        int responses = 0, last_e = -1;
        Vec3 last_y_surface = Vec3::Zero();
        auto respond = [&](int e) __attribute__((always_inline)) {
            const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
            const Vec3 d = xp - f.center;
            const Vec3 y = f.to_unit * d;
            const Real y_sq = y.squaredNorm();
            if (y_sq >= 1) return false;
            const Real y_len = std::sqrt(y_sq);
            const Real inv_len = 1 / y_len;
            const Real depth = centre_line_depth(f, d, y_len, inv_len);
            const Real allowed = y_len > Real(1e-6) ? allowance(e, xp) : Real(0);
            if (depth <= allowed + give_tolerance_m && allowed > 0) return false;
            if (responses == 0 && e == first) r.max_penetration_m = std::max(r.max_penetration_m, depth - allowed);
            if (allowed > 0)  // along the centre line to the allowance: |d| / |y| metres per unit of |y|
                last_y_surface = place_on_surface(f, y, xp, 1 - allowed * y_len / d.norm());
            else
                last_y_surface = place_shortest(f, y, y_sq, inv_len, depth, xp, outside[static_cast<std::size_t>(e)]);
            last_e = e;
            ++responses;
            ++r.collisions;
            return true;
        };
        for_each_bit(hits & last, respond);
        for_each_bit(hits & ~last, respond);
        // Pushed beyond what the list still covers: every ellipsoid may now be near.
        const Real slack = list_slack.size() == static_cast<std::size_t>(n) ? list_slack[pi] : std::numeric_limits<Real>::infinity();
        const Real slack_sq = slack * slack;
        std::uint64_t retest = (xp - x_detected).squaredNorm() > slack_sq ? active : list;
        bool fell_back = false;
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
                const bool hangs = above.size() == static_cast<std::size_t>(n) && above[pi] != static_cast<std::uint32_t>(p);
                xp = fallback_exit(frames, active, x_detected, hits, xp,
                                   hangs ? Vec3(x.col(static_cast<Eigen::Index>(above[pi]))) : x_detected);
                fell_back = true;
                Real depth = 0;
                for_each_bit(active, [&](int e) {
                    ++r.tests;
                    depth = std::max(depth, penetration_depth(frames[static_cast<std::size_t>(e)], xp));
                });
                if (depth > Real(1e-5)) ++r.unresolved;
            }
        }
        // Velocity: the push itself is not motion. What the particle had before it (its
        // move up to the contact) keeps its part along each surface touched only where it
        // does not approach that surface's own motion; Coulomb friction slows the tangential
        // part by friction x the approach removed.
        const bool single = responses == 1 && !fell_back;
        if (respond_velocity) for_each_bit(last_collided[pi], [&](int e) {
            const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
            const Vec3 normal = surface_normal(f, single && e == last_e ? last_y_surface : to_unit_sphere(f, xp));
            const Vec3 surface_velocity = body_velocity_at(f, xp);
            const Vec3 relative = vp - surface_velocity;
            const Real approach = relative.dot(normal);
            if (approach >= 0) return;
            Vec3 tangential = relative - approach * normal;
            const Real t_len = tangential.norm();
            if (t_len > 0) tangential *= std::max(Real(0), 1 + friction * approach / t_len);  // approach < 0
            vp = surface_velocity + tangential;
        });
        x.col(p) = xp;
        v.col(p) = vp;
    };

    if (!listed.empty()) {
        // A few particles on their own: each tested against its list without vector lanes.
        for (const std::uint32_t p : listed) {
            const auto pi = static_cast<Eigen::Index>(p);
            if (pi < first || pi >= end) continue;
            const std::uint64_t list = inv_mass[pi] != 0 ? (candidates ? (*candidates)[p] & active : active) : 0;
            r.tests += static_cast<std::uint64_t>(std::popcount(list));
            std::uint64_t hits = 0;
            if (detect_one(x, pi, frames, list, hits)) {
                collide_one(pi, hits);
            } else {
                last_collided[p] = 0;
                if (detected) (*detected)[p] = 0;
            }
        }
        return r;
    }
    // 64 particles at a time against the ellipsoids of their lists (detect_block); brute
    // force lists every active ellipsoid for every free particle, through the same code.
    LaneBits block_lists{}, block_hits{};
    for (Eigen::Index begin = first; begin < end; begin += detect_lanes) {
        const Eigen::Index count = std::min(detect_lanes, end - begin);
        const std::size_t bi = static_cast<std::size_t>(begin);
        block_lists.fill(0);
        std::uint64_t any = 0;
        for (Eigen::Index l = 0; l < count; ++l) {
            const std::size_t li = static_cast<std::size_t>(l);
            const std::uint64_t list = candidates ? (*candidates)[bi + li] & active : active;
            block_lists[li] = inv_mass[begin + l] != 0 ? list : 0;  // pinned: none
            r.tests += static_cast<std::uint64_t>(std::popcount(block_lists[li]));
            any |= block_lists[li];
        }
        block_hits.fill(0);
        if (any == 0 || !detect_block(x, begin, count, frames, block_lists, block_hits)) {  // no contact
            std::fill_n(last_collided.begin() + static_cast<std::ptrdiff_t>(bi), count, 0);
            if (detected) std::fill_n(detected->begin() + static_cast<std::ptrdiff_t>(bi), count, 0);
            continue;
        }
        for (Eigen::Index l = 0; l < count; ++l) {
            const std::size_t li = static_cast<std::size_t>(l);
            if (block_hits[li] != 0) {
                collide_one(begin + l, block_hits[li]);
            } else {
                last_collided[bi + li] = 0;
                if (detected) (*detected)[bi + li] = 0;
            }
        }
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

// Colliders whose own move since their reference enters a particle's bound of its room
// exactly (update_candidate_part step 3): the ones that moved most (a swinging foot, a hand).
constexpr std::size_t fast_colliders = 4;

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

void prepare_candidate_lists(Garment& g, GarmentSolver& solver) {
    CandidateLists& lists = solver.lists;
    const Eigen::Index n = g.state.x.cols();
    const std::size_t e_count = std::min<std::size_t>(solver.frames.size(), 64);
    const std::size_t parts = solver.parts.runs.size();
    const bool valid = lists.valid && lists.parts.size() == parts && lists.reference_x.cols() == n &&
                       lists.clearance_m.rows() == n && lists.clearance_m.cols() == static_cast<Eigen::Index>(e_count) &&
                       lists.bits.size() == static_cast<std::size_t>(n) && lists.min_clearance_m.size() == n &&
                       std::all_of(lists.parts.begin(), lists.parts.end(),
                                   [&](const CandidateListPart& p) { return p.reference_frames.size() == e_count; });
    lists.scratch.resize(3, n);
    lists.slack_m.resize(n);
    if (valid) return;
    // Everything from scratch: every particle and every ellipsoid is its own reference.
    lists.parts.assign(parts, CandidateListPart{});
    lists.bits.assign(static_cast<std::size_t>(n), 0);
    lists.reference_x.resize(3, n);
    lists.clearance_m.setConstant(n, static_cast<Eigen::Index>(e_count), std::numeric_limits<Real>::infinity());
    lists.min_clearance_m.setConstant(n, std::numeric_limits<Real>::infinity());
    lists.valid = true;
    ++g.counters.list_rebuilds;
}

void update_candidate_part(const Garment& g, GarmentSolver& solver, std::size_t part_index, PartCounters& counters) {
    CandidateLists& lists = solver.lists;
    CandidateListPart& part = lists.parts[part_index];
    const std::vector<ParticleRun>& runs = solver.parts.runs[part_index];
    const std::size_t e_count = std::min<std::size_t>(solver.frames.size(), 64);
    const Affine3 anchor = anchor_frame(solver.frames, g.body.anchor);
    const Mat3 to_anchor = anchor.linear().transpose();  // rigid: inverse = transpose
    const Real margin = g.config.material.candidate_margin_m;
    auto& clearance = lists.clearance_m;  // particle x ellipsoid, column e contiguous
    VectorX& slack = lists.slack_m;
    std::uint64_t tests = 0;

    // 1. Each particle's position and move d_p in the anchor frame (whole runs).
    Matrix3XRows& local = lists.scratch;
    const bool rebuild = !part.valid;  // every particle and every ellipsoid is its own reference
    if (rebuild) part.reference_frames.assign(e_count, Affine3(Eigen::Matrix<Real, 4, 4>::Zero()));
    for (const auto [first, n] : runs) {
        // One pass with stride-3 loads; the rows of `local` are contiguous.
        const Vec3 t = anchor.translation();
        const Real* x = g.state.x.data();
        Real* l0 = local.row(0).data();
        Real* l1 = local.row(1).data();
        Real* l2 = local.row(2).data();
        const Mat3& r = to_anchor;
        for (Eigen::Index p = first; p < n; ++p) {
            const Real a = x[3 * p] - t[0], b = x[3 * p + 1] - t[1], c = x[3 * p + 2] - t[2];
            l0[p] = r(0, 0) * a + r(0, 1) * b + r(0, 2) * c;
            l1[p] = r(1, 0) * a + r(1, 1) * b + r(1, 2) * c;
            l2[p] = r(2, 0) * a + r(2, 1) * b + r(2, 2) * c;
        }
        const Eigen::Index count = n - first;
        if (rebuild) lists.reference_x.middleCols(first, count) = local.middleCols(first, count);
        const auto d = (local.middleCols(first, count) - lists.reference_x.middleCols(first, count)).array();
        slack.segment(first, count) = (d.row(0).square() + d.row(1).square() + d.row(2).square()).sqrt().transpose();
    }

    // 2. Ellipsoids: refresh bit e against the particles' reference points when e has moved
    //    its share since its reference pose, which it then becomes. D_e: its move since.
    std::vector<BlockBounds> bounds;  // of the reference points of each run, on first use
    const Real ellipsoid_limit = ellipsoid_refresh_share * margin;
    std::array<Real, 64> moved_since{};
    for (std::size_t e = 0; e < e_count; ++e) {
        Affine3& then = part.reference_frames[e];
        if (!solver.frames[e].active) {
            if (has_reference(then)) {
                for (const auto [first, n] : runs) {
                    for (Eigen::Index p = first; p < n; ++p) lists.bits[static_cast<std::size_t>(p)] &= ~(std::uint64_t(1) << e);
                    clearance.col(static_cast<Eigen::Index>(e)).segment(first, n - first).setConstant(std::numeric_limits<Real>::infinity());
                }
                then.matrix().setZero();
            }
            continue;
        }
        const EllipsoidFrame current = in_anchor_frame(solver.frames[e], anchor);
        const Affine3 now = unit_to_world(current);
        const Real moved = has_reference(then) ? ellipsoid_move(now, then) : std::numeric_limits<Real>::infinity();
        if (moved <= ellipsoid_limit) {
            moved_since[e] = moved;
            continue;
        }
        if (bounds.empty())
            for (const auto [first, n] : runs) bounds.emplace_back(lists.reference_x, first, n);
        for (std::size_t r = 0; r < runs.size(); ++r) {
            const auto [first, n] = runs[r];
            tests += refresh_bit(lists.reference_x, first, n, bounds[r], ListEllipsoid(current), e, margin, lists.bits,
                                 clearance.col(static_cast<Eigen::Index>(e)).data());
            auto least = lists.min_clearance_m.segment(first, n - first);
            least = least.cwiseMin(clearance.col(static_cast<Eigen::Index>(e)).segment(first, n - first));
        }
        then = now;
    }

    // 3. Particles: a list is exact while d_p + D_e < C_pe for every unlisted e, the
    //    clearance between their references: the slack is min_e (C_pe - D_e) - d_p. First
    //    its lower bound min_e C_pe - max_e D_e - d_p from the kept least clearance, one
    //    column; where that is negative, the exact minimum (and the least clearance made
    //    exact again). A particle without slack becomes its own reference and is tested
    //    against every reference ellipsoid.
    //    The colliders that moved most (at most fast_colliders) enter that bound exactly,
    //    C_pe - D_e column by column, the others as min_e C_pe less the most any of them
    //    moved: still a lower bound, so the same particles are spent, and fewer need the
    //    exact minimum.
    const std::uint64_t active = active_mask(solver.frames);
    std::array<int, fast_colliders> fast;
    fast.fill(-1);
    for_each_bit(active, [&](int e) {  // kept in order, the most moved first
        for (int& slot : fast) {
            if (slot < 0) {
                slot = e;
                break;
            }
            if (moved_since[static_cast<std::size_t>(e)] > moved_since[static_cast<std::size_t>(slot)]) std::swap(slot, e);
        }
    });
    Real rest_moved = 0;
    for_each_bit(active, [&](int e) {
        if (std::find(fast.begin(), fast.end(), e) == fast.end())
            rest_moved = std::max(rest_moved, moved_since[static_cast<std::size_t>(e)]);
    });
    std::optional<ReferenceLanes> references;  // on first use
    alignas(64) std::array<Real, ReferenceLanes::max_lanes> stored;
    std::vector<Eigen::Index>& spent = part.spent;
    Real* least = lists.min_clearance_m.data();
    VectorX& room = part.room;
    for (const auto [first, n] : runs) {
        const Eigen::Index count = n - first;
        room.resize(count);
        room = lists.min_clearance_m.segment(first, count).array() - rest_moved;
        for (const int e : fast)
            if (e >= 0)
                room = room.cwiseMin((clearance.col(e).segment(first, count).array() - moved_since[static_cast<std::size_t>(e)]).matrix());
        slack.segment(first, count) = room - slack.segment(first, count);  // slack held d_p
        for (Eigen::Index p = first; p < n; ++p) {
            if (slack[p] >= 0) continue;
            Real room = std::numeric_limits<Real>::infinity(), exact = std::numeric_limits<Real>::infinity();
            for_each_bit(active, [&](int e) {
                const Real c = clearance(p, e);
                room = std::min(room, c - moved_since[static_cast<std::size_t>(e)]);
                exact = std::min(exact, c);
            });
            least[p] = exact;
            const auto d = local.col(p) - lists.reference_x.col(p);
            slack[p] = room - std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        }
        // The particles without slack, gathered without a branch per particle; pinned ones
        // are never tested (method §3.5).
        spent.resize(static_cast<std::size_t>(count));
        std::size_t spent_count = 0;
        for (Eigen::Index begin = first; begin < n; begin += 16) {
            const Eigen::Index end = std::min<Eigen::Index>(begin + 16, n);
            if (end - begin == 16 && Eigen::Map<const Eigen::Array<Real, 16, 1>>(slack.data() + begin).minCoeff() >= 0) continue;
            for (Eigen::Index p = begin; p < end; ++p) {
                spent[spent_count] = p;
                spent_count += static_cast<std::size_t>(slack[p] < 0) & static_cast<std::size_t>(g.state.inv_mass[p] != 0);
            }
        }
        for (std::size_t k = 0; k < spent_count; ++k) {
            const Eigen::Index p = spent[k];
            if (!references) {
                references.emplace(e_count);
                for_each_bit(active, [&](int e) {
                    const std::size_t ei = static_cast<std::size_t>(e);
                    references->set(ei, part.reference_frames[ei], moved_since[ei]);
                });
            }
            lists.reference_x.col(p) = local.col(p);
            Real left = 0;
            lists.bits[static_cast<std::size_t>(p)] = references->test(local.col(p), margin, stored, left);
            Real exact = std::numeric_limits<Real>::infinity();
            for (std::size_t e = 0; e < e_count; ++e) {
                clearance(p, static_cast<Eigen::Index>(e)) = stored[e];
                exact = std::min(exact, stored[e]);
            }
            least[p] = exact;
            slack[p] = std::max(Real(0), left);
            tests += static_cast<std::uint64_t>(std::popcount(active));
        }
    }
    part.valid = true;
    part.frames_serial = solver.frames_serial;
    counters.list_tests += tests;
}

void update_candidate_lists(Garment& g, GarmentSolver& solver) {
    prepare_candidate_lists(g, solver);
    PartCounters counters;
    for (std::size_t k = 0; k < solver.lists.parts.size(); ++k) update_candidate_part(g, solver, k, counters);
    add_part_counters(g, counters);
}

void add_part_counters(Garment& g, const PartCounters& c) {
    GarmentCounters& gc = g.counters;
    gc.list_rebuild_tests += c.list_tests;
    gc.frame_list_rebuild_tests += c.list_tests;
    gc.frame_collision_tests += c.collision_tests;
    gc.collision_tests += c.collision_tests;
    gc.frame_collisions += c.collisions;
    gc.collisions += c.collisions;
    gc.max_penetration_m = std::max(gc.max_penetration_m, c.max_penetration_m);
}

CollisionResult collide_part(const Garment& g, GarmentSolver& solver, Matrix3X& x, Matrix3X& v, Eigen::Index first,
                             Eigen::Index end, bool respond_velocity, PartCounters& counters, DetectedPairs* detected) {
    const std::vector<std::uint64_t>* lists = nullptr;
    std::span<const Real> slack;
    if (g.config.collision == CollisionMode::candidate_lists) {
        lists = &solver.lists.bits;
        slack = std::span<const Real>(solver.lists.slack_m.data(), static_cast<std::size_t>(solver.lists.slack_m.size()));
    }
    const CollisionResult r = collide_particles(x, v, g.state.inv_mass, solver.frames, lists, solver.last_collided, detected,
                                                g.config.material.friction, slack, first, end, respond_velocity, solver.above);
    counters.collision_tests += r.tests;
    counters.collisions += r.collisions;
    counters.max_penetration_m = std::max(counters.max_penetration_m, r.max_penetration_m);
    return r;
}

CollisionResult collide_range(Garment& g, GarmentSolver& solver, Eigen::Index first, Eigen::Index end, DetectedPairs* detected,
                              bool respond_velocity) {
    if (g.config.collision == CollisionMode::candidate_lists && !solver.lists.valid) update_candidate_lists(g, solver);
    PartCounters counters;
    const CollisionResult r = collide_part(g, solver, g.state.x, g.state.v, first, end, respond_velocity, counters, detected);
    add_part_counters(g, counters);
    return r;
}

Real ground_height(const Registry& registry) {
    Real height = -std::numeric_limits<Real>::infinity();
    registry.each<GroundPlane>([&](Entity, const GroundPlane& ground) { height = std::max(height, ground.height_m); });
    return height;
}

std::uint64_t collide_ground(Matrix3X& x, const VectorX& inv_mass, Real ground_m, Eigen::Index first, Eigen::Index end,
                             Matrix3X* push) {
    std::uint64_t moved = 0;
    if (!(ground_m > -std::numeric_limits<Real>::infinity()) || end <= first) return moved;
    // Most rounds nothing is near the floor: the lowest particle first, without a branch.
    Real lowest = std::numeric_limits<Real>::infinity();
    const Real* y = x.data() + 1;
    for (Eigen::Index p = first; p < end; ++p) lowest = std::min(lowest, y[3 * p]);
    if (!(lowest < ground_m)) return moved;
    for (Eigen::Index p = first; p < end; ++p) {
        const Real below = ground_m - x(1, p);
        if (!(below > 0) || inv_mass[p] == 0) continue;
        x(1, p) = ground_m;
        if (push) (*push)(1, p) += below;
        ++moved;
    }
    return moved;
}

CollisionResult collide_garment(Garment& g, GarmentSolver& solver, DetectedPairs* detected) {
    if (g.config.collision == CollisionMode::candidate_lists) update_candidate_lists(g, solver);
    return collide_range(g, solver, 0, g.state.x.cols(), detected);
}

}  // namespace drape
