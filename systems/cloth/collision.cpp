// Particle-ellipsoid collision (method §5); step order in collision.hpp.
#include "systems/cloth/collision.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
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

// Distance along the ray o + t d (|d| = 1) at which it leaves the ellipsoid; -inf if it misses.
// In double: the quadratic loses digits when the ray is nearly tangent.
inline Real ray_exit(const EllipsoidFrame& f, const Vec3& o, const Vec3& d) {
    const Eigen::Vector3d oo = to_unit_sphere(f, o).cast<double>();
    const Eigen::Vector3d dd = (f.to_unit * d).cast<double>();
    const double a = dd.squaredNorm(), b = 2 * oo.dot(dd), c = oo.squaredNorm() - 1;
    const double disc = b * b - 4 * a * c;
    if (disc < 0 || a <= 0) return -std::numeric_limits<Real>::infinity();
    return static_cast<Real>((-b + std::sqrt(disc)) / (2 * a));
}

// The response of one contact (method §5): onto the surface along the centre line, or
// along the outward normal at the particle when that way out is shorter. Deep inside an
// elongated ellipsoid (a thigh the hem swung into) the centre line runs along the long axis
// and would carry the particle tens of centimetres toward the knee; the normal leaves by
// the short side. Near the surface both agree.
inline void respond_shortest(const EllipsoidFrame& f, const Vec3& y, Vec3& x, Vec3& v) {
    const Real y_length = y.norm();
    if (y_length > Real(1e-6)) {
        const Vec3 normal = (f.to_unit.transpose() * y).normalized();
        const Real along_normal = ray_exit(f, x, normal);
        const Real along_centre = (x - f.center).norm() * (1 / y_length - 1);
        if (along_normal >= 0 && along_normal < along_centre) {
            // push_out only rescales this point's unit-sphere image onto the surface (+ clearance).
            push_out(f, to_unit_sphere(f, x + along_normal * normal), x, v);
            return;
        }
    }
    push_out(f, y, x, v);
}

template <class F>
inline void for_each_bit(std::uint64_t bits, F&& f) {
    while (bits != 0) {
        const int e = std::countr_zero(bits);
        bits &= bits - 1;
        f(e);
    }
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

void push_out(const EllipsoidFrame& f, const Vec3& y_in, Vec3& x, Vec3& v) {
    Vec3 y = y_in;
    Real length = y.norm();
    if (length <= Real(1e-6)) {  // at the centre: no centre line; leave along the longest axis
        Eigen::Index axis = 0;
        f.radii_m.maxCoeff(&axis);
        y = Vec3::Unit(axis);
        length = 1;
    }
    const Vec3 y_surface = y * ((1 + surface_clearance(f)) / length);
    x = f.center + f.rotation * f.radii_m.cwiseProduct(y_surface);
    const Vec3 normal = (f.to_unit.transpose() * y_surface).normalized();
    const Vec3 surface_velocity = body_velocity_at(f, x);
    const Real approach = (v - surface_velocity).dot(normal);
    if (approach < 0) v -= approach * normal;
}

std::uint64_t active_mask(std::span<const EllipsoidFrame> frames) {
    std::uint64_t mask = 0;
    for (std::size_t e = 0; e < frames.size() && e < 64; ++e)
        if (frames[e].active) mask |= std::uint64_t(1) << e;
    return mask;
}

std::uint64_t build_candidate_lists(const Matrix3X& x, std::span<const EllipsoidFrame> frames, Real margin,
                                    std::vector<std::uint64_t>& candidates, Matrix3X* scratch) {
    const Eigen::Index n = x.cols();
    candidates.assign(static_cast<std::size_t>(n), 0);
    Matrix3X local_scratch;
    Matrix3X& y = scratch ? *scratch : local_scratch;
    y.resize(3, n);  // no allocation when the scratch is already sized
    std::uint64_t tests = 0;
    if (n == 0) return 0;
    const Vec3 low = x.rowwise().minCoeff(), high = x.rowwise().maxCoeff();
    for (std::size_t e = 0; e < frames.size() && e < 64; ++e) {
        const EllipsoidFrame& f = frames[e];
        if (!f.active) continue;
        const Real reach = 1 + margin / f.radii_m.minCoeff();
        const Real reach_sq = reach * reach;
        // The reach region's bounding box misses the garment's: no particle can list it.
        const Vec3 half = reach * (f.rotation * f.radii_m.asDiagonal()).rowwise().norm();
        if (((f.center - half).array() > high.array()).any() || ((f.center + half).array() < low.array()).any()) continue;
        const std::uint64_t bit = std::uint64_t(1) << e;
        // Whole-array unit-sphere map, then one compare per particle.
        y.noalias() = f.to_unit * x;
        const Vec3 offset = f.to_unit * f.center;
        for (Eigen::Index p = 0; p < n; ++p)
            if ((y.col(p) - offset).squaredNorm() <= reach_sq) candidates[static_cast<std::size_t>(p)] |= bit;
        tests += static_cast<std::uint64_t>(n);
    }
    return tests;
}

CollisionResult collide_particles(Matrix3X& x, Matrix3X& v, const VectorX& inv_mass,
                                  std::span<const EllipsoidFrame> frames, const std::vector<std::uint64_t>* candidates,
                                  std::vector<std::uint64_t>& last_collided, DetectedPairs* detected,
                                  const Matrix3X* x_start, Real h, Real list_slack) {
    CollisionResult r;
    const Eigen::Index n = x.cols();
    last_collided.resize(static_cast<std::size_t>(n), 0);
    if (detected) detected->assign(static_cast<std::size_t>(n), 0);
    const std::uint64_t active = active_mask(frames);

    for (Eigen::Index p = 0; p < n; ++p) {
        const std::size_t pi = static_cast<std::size_t>(p);
        if (inv_mass[p] == 0) {
            last_collided[pi] = 0;
            continue;
        }
        const std::uint64_t list = (candidates ? (*candidates)[pi] : ~std::uint64_t(0)) & active;
        const std::uint64_t last = last_collided[pi] & list;
        Vec3 xp = x.col(p);
        std::uint64_t hits = 0;
        auto detect = [&](int e) {
            ++r.tests;
            const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
            const Vec3 y = to_unit_sphere(f, xp);
            const Real y_sq = y.squaredNorm();
            if (y_sq >= 1) return;
            hits |= std::uint64_t(1) << e;
            const Real y_len = std::sqrt(y_sq);
            const Real depth = y_len > Real(1e-6) ? (xp - f.center).norm() * (1 / y_len - 1) : f.radii_m.minCoeff();
            r.max_penetration_m = std::max(r.max_penetration_m, depth);
        };
        for_each_bit(last, detect);          // temporal coherence: last substep's contacts first
        for_each_bit(list & ~last, detect);  // then the rest of the pre-collision list
        if (detected) (*detected)[pi] = hits;
        last_collided[pi] = hits;
        if (hits == 0) continue;

        Vec3 vp = v.col(p);
        const Vec3 x_detected = xp;
        auto respond = [&](int e) {
            const EllipsoidFrame& f = frames[static_cast<std::size_t>(e)];
            const Vec3 y = to_unit_sphere(f, xp);
            if (y.squaredNorm() >= 1) return false;
            respond_shortest(f, y, xp, vp);
            ++r.collisions;
            return true;
        };
        for_each_bit(hits & last, respond);
        for_each_bit(hits & ~last, respond);
        // Pushed beyond what the list still covers: every ellipsoid may now be near.
        const Real slack_sq = list_slack * list_slack;
        std::uint64_t retest = (xp - x_detected).squaredNorm() > slack_sq ? active : list;
        if (std::popcount(retest) > 1 || retest != list) {
            bool moved = true;
            for (int round = 0; round < max_retest_rounds && moved; ++round) {
                moved = false;
                if ((xp - x_detected).squaredNorm() > slack_sq) retest = active;
                for_each_bit(retest, [&](int e) {
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
        if (x_start != nullptr && h > 0) {
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
    DetectedPairs out(static_cast<std::size_t>(x.cols()), 0);
    for (Eigen::Index p = 0; p < x.cols(); ++p) {
        if (inv_mass[p] == 0) continue;
        for (std::size_t e = 0; e < frames.size() && e < 64; ++e)
            if (frames[e].active && to_unit_sphere(frames[e], x.col(p)).squaredNorm() < 1)
                out[static_cast<std::size_t>(p)] |= std::uint64_t(1) << e;
    }
    return out;
}

CollisionResult collide_garment(Garment& g, DetectedPairs* detected, Real h) {
    const Eigen::Index n = g.x.cols();
    const std::size_t e_count = g.frames.size();
    const std::vector<std::uint64_t>* lists = nullptr;
    Real slack = std::numeric_limits<Real>::infinity();

    if (g.collision == CollisionMode::candidate_lists) {
        const Affine3 anchor = anchor_frame(g);
        const Mat3 to_anchor = anchor.linear().transpose();  // rigid: inverse = transpose
        const Vec3 anchor_origin = anchor.translation();
        const Real margin = g.material.candidate_margin_m;
        bool valid = g.lists_valid && g.list_anchor_frames.size() == e_count && g.list_anchor_x.cols() == n &&
                     g.candidates.size() == static_cast<std::size_t>(n) && g.list_epoch_move.size() == static_cast<std::size_t>(n);
        Real frame_move = 0;
        for (std::size_t e = 0; valid && e < e_count; ++e) {
            const Affine3& then = g.list_anchor_frames[e];
            const bool was_active = then.linear().squaredNorm() > 0;
            if (was_active != g.frames[e].active) { valid = false; break; }
            if (!was_active) continue;
            const Affine3 world = unit_to_world(g.frames[e]);
            const Vec3 c = to_anchor * (world.translation() - anchor_origin);
            const Mat3 l = to_anchor * world.linear();
            frame_move = std::max(frame_move, (c - then.translation()).norm() + (l - then.linear()).norm());
        }
        // A global rebuild (new epoch) once the ellipsoids have used half the margin.
        if (valid && frame_move > margin / 2) valid = false;
        if (!valid) {
            const std::uint64_t tests = build_candidate_lists(g.x, g.frames, margin, g.candidates, &g.force);
            g.list_anchor_x.resize(3, n);
            for (Eigen::Index p = 0; p < n; ++p) g.list_anchor_x.col(p) = to_anchor * (g.x.col(p) - anchor_origin);
            g.list_epoch_move.assign(static_cast<std::size_t>(n), 0);
            g.list_anchor_frames.resize(e_count);
            for (std::size_t e = 0; e < e_count; ++e) {
                Affine3& then = g.list_anchor_frames[e];
                if (!g.frames[e].active) {
                    then.matrix().setZero();
                    continue;
                }
                const Affine3 world = unit_to_world(g.frames[e]);
                then.setIdentity();
                then.linear() = to_anchor * world.linear();
                then.translation() = to_anchor * (world.translation() - anchor_origin);
            }
            g.lists_valid = true;
            frame_move = 0;
            ++g.counters.list_rebuilds;
            g.counters.list_rebuild_tests += tests;
            g.counters.frame_list_rebuild_tests += tests;
        }
        // Per particle: its list, built when the ellipsoids had moved epoch_move since the
        // epoch, stays exact while its own move + epoch_move + frame_move <= margin.
        // A particle past that bound gets a fresh list on its own.
        slack = margin;
        std::uint64_t particle_tests = 0;
        const std::uint64_t active = active_mask(g.frames);
        const int active_count = std::popcount(active);
        for (Eigen::Index p = 0; p < n; ++p) {
            const std::size_t pi = static_cast<std::size_t>(p);
            const Vec3 local = to_anchor * (g.x.col(p) - anchor_origin);
            Real room = margin - frame_move - g.list_epoch_move[pi] - (local - g.list_anchor_x.col(p)).norm();
            if (room < 0) {
                std::uint64_t bits = 0;
                for_each_bit(active, [&](int e) {
                    const EllipsoidFrame& f = g.frames[static_cast<std::size_t>(e)];
                    const Real reach = 1 + margin / f.radii_m.minCoeff();
                    if (to_unit_sphere(f, g.x.col(p)).squaredNorm() <= reach * reach) bits |= std::uint64_t(1) << e;
                });
                g.candidates[pi] = bits;
                g.list_anchor_x.col(p) = local;
                g.list_epoch_move[pi] = frame_move;
                particle_tests += static_cast<std::uint64_t>(active_count);
                room = margin - 2 * frame_move;
            }
            slack = std::min(slack, room);
        }
        g.counters.list_rebuild_tests += particle_tests;
        g.counters.frame_list_rebuild_tests += particle_tests;
        lists = &g.candidates;
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
