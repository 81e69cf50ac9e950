// Particle-ellipsoid collision with candidate lists and temporal coherence (method §5).
//
// Conventions: only particles are tested, never triangles; each test maps the particle into
// the ellipsoid's unit-sphere frame, y = diag(1/r) R^T (x - c), and asks |y| < 1.
//
// Step order of one substep (cloth collision system):
//   1. Candidate lists (spatial locality): each particle keeps a bit set of the ellipsoids
//      it can touch: bit e is set when the particle is within `margin` of ellipsoid e,
//      judged by a lower bound of the distance (clearance) that needs no root finding:
//      max(r_min (|y| - 1), max_i r_i (|y_i| - 1)). Everything is measured in the anchor's
//      rigid frame against references: each particle's position when its whole list was
//      last refreshed (its move since: d_p) and each ellipsoid's pose when its bit was last
//      refreshed (its move since, D_e <= |dc| + |dL|_F of its unit-sphere map). Each
//      particle keeps C_pe, the clearance of its reference point from each unlisted
//      reference ellipsoid; while d_p + D_e < C_pe for every unlisted e, none of them can
//      contain it. An ellipsoid that has moved half the margin gets its bit (and C_pe)
//      refreshed in every list (a fast shin often, the pelvis rarely; blocks of particles
//      whose box is far from it are cleared untested); a particle with no slack left,
//      min_e (C_pe - D_e) - d_p, gets its whole list refreshed. The slack is first taken
//      from a kept lower bound of min_e C_pe less the largest D_e, and exactly only where
//      that bound runs out. The slack (at most the exact one) is kept for step 3.
//      A garment cut into bands (garment_parts.hpp) keeps the ellipsoid references per band,
//      so that bands are brought up to date independently, on different threads.
//   2. Detection: in list mode 64 consecutive particles are tested at once against every
//      ellipsoid of their lists (vector lanes outside a particle's list are discarded and not
//      counted); brute force tests every ellipsoid. Last substep's contacts are answered
//      first (temporal coherence).
//   3. Response for each hit, last-collided first: move the particle to where the line
//      from the centre through it meets the surface, x = c + (x - c) / |y|, and remove the
//      velocity component along the surface normal relative to the surface's own motion
//      (the ellipsoid is inelastic); when the surface is nearer along the outward normal
//      at the particle (deep in an elongated ellipsoid), along that normal instead.
//      Overlapping ellipsoids can push a particle into a neighbour, so the particle's list
//      is re-tested until it is outside all of them (every ellipsoid, when the push went
//      beyond what the list bound still covers); after a few rounds it leaves from where it
//      was detected by the shortest of a few straight ways out past every ellipsoid, one of
//      them toward the particle above it on its warp line (the cloth it hangs from).
//      An ellipsoid that gives (EllipsoidCollider::give_m: a forearm's or a hand's bulge
//      over its skin) leaves a particle inside it where it lies no deeper than its give less
//      the particle's distance outside the nearest ellipsoid that does not give (a lower
//      bound, the list clearance below); a particle deeper goes along the centre line to
//      that depth. Cloth caught between a forearm and the hips keeps to the hips. A particle
//      left within a give is in contact all the same: its approach to that ellipsoid is
//      removed and friction applied, as at any contact (a soft surface).
//      Within a substep, a particle that collided takes the velocity of its whole move,
//      (x_end - x_start) / h, before the normal component is removed: the constraints
//      and the push-out then cannot pump energy into a particle held against the body.
// Pinned particles are skipped: they are on the skin by construction (method §3.5).
//
// The floor (components/ground_plane.hpp) is not one of the paper's colliders: a game puts
// its characters on one, and a long dress reaches it. After each collision round and after
// the contact repair, a free particle below it is moved straight up onto it; the velocity
// update then treats the floor as one more surface, at rest, with the same friction. The
// floor has the last word: a foot's ellipsoid reaches below the sole, and cloth stepped on
// stays on the floor under it (measured as a penetration of the foot's ellipsoid). Moving
// such cloth out of the foot, along the floor or up over it, was tried: the jumps tore a
// floor-length hem on the walk (157 % against 10 %).
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "drape/components/garment.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/cloth/garment_solver.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// Unit-sphere coordinates of x in the ellipsoid's frame.
[[nodiscard]] inline Vec3 to_unit_sphere(const EllipsoidFrame& f, const Vec3& x) { return f.to_unit * (x - f.center); }

/// Distance the centre-line response would move `x` out of the ellipsoid (0 when outside), m.
[[nodiscard]] Real penetration_depth(const EllipsoidFrame& f, const Vec3& x);

/// How far x lies inside ellipsoid `frames[e]` past what its give allows there
/// (EllipsoidCollider::give_m: the give less x's distance outside the nearest active
/// ellipsoid that does not give); penetration_depth for an ellipsoid without give.
[[nodiscard]] Real depth_past_give(std::span<const EllipsoidFrame> frames, std::size_t e, const Vec3& x);

/// The nearest place outside the ellipsoid for a point inside it, by the shortest of the
/// normal and the centre line (the contact response's rule), plus the clearance; a point
/// outside is returned as it is.
[[nodiscard]] Vec3 leave_ellipsoid(const EllipsoidFrame& f, const Vec3& x);

/// Entry and exit distances of the ray o + t d (|d| = 1) through the ellipsoid; in > out
/// where the ray misses it.
[[nodiscard]] std::pair<Real, Real> ray_span(const EllipsoidFrame& f, const Vec3& o, const Vec3& d);

/// The smallest t >= 0 at which o + t d (|d| = 1) lies outside every ellipsoid of `frames`
/// in the bit set `set` (active ones only), plus the clearance past the last one it leaves;
/// it stops early once t exceeds `give_up`.
[[nodiscard]] Real first_point_outside(std::span<const EllipsoidFrame> frames, std::uint64_t set, const Vec3& o,
                                       const Vec3& d, Real give_up = std::numeric_limits<Real>::infinity());

/// Moves x onto the surface along the centre line and removes the normal velocity
/// relative to the surface (method §5). `y` = to_unit_sphere(f, x), |y| < 1.
void push_out(const EllipsoidFrame& f, const Vec3& y, Vec3& x, Vec3& v);

/// Bit set of the active frames.
[[nodiscard]] std::uint64_t active_mask(std::span<const EllipsoidFrame> frames);

/// Sets bit `e` of every particle's candidate list when the particle is within `margin_m`
/// of ellipsoid e (see step 1) and clears it otherwise; an inactive or missing ellipsoid
/// clears it everywhere. Other bits are kept. Returns the tests done: blocks of particles
/// whose bounding box misses the ellipsoid's reach are cleared untested.
std::uint64_t refresh_candidate_bit(const Matrix3X& x, std::span<const EllipsoidFrame> frames, std::size_t e,
                                    Real margin_m, std::vector<std::uint64_t>& candidates);

/// Rebuilds every particle's candidate list from scratch (every bit). Returns the tests done.
std::uint64_t build_candidate_lists(const Matrix3X& x, std::span<const EllipsoidFrame> frames, Real margin_m,
                                    std::vector<std::uint64_t>& candidates);

/// Step 1 for a garment: brings its candidate lists up to date for its current positions
/// and the solver's frames (everything when the lists are not valid or the sizes changed,
/// else the bits of ellipsoids and the lists of particles whose bound is spent), adds the
/// tests to its counters and leaves in `lists.slack_m` how far each free particle may still
/// move before its list could miss an ellipsoid (>= 0).
void update_candidate_lists(Garment& garment, GarmentSolver& solver);

/// Step 1 in parts (garment_parts.hpp), as update_candidate_lists does it: first, on one
/// thread, the lists sized for the garment (all rebuilt when they were not valid or a size
/// changed); then each particle range of solver.parts on its own, at the same time as the
/// others (each keeps its own collider references), its tests added to `counters`.
void prepare_candidate_lists(Garment& garment, GarmentSolver& solver);
void update_candidate_part(const Garment& garment, GarmentSolver& solver, std::size_t part, PartCounters& counters);

/// Adds a part's counts to the garment's counters.
void add_part_counters(Garment& garment, const PartCounters& counters);

/// What a collision pass did.
struct CollisionResult {
    std::uint64_t tests = 0;          ///< Unit-sphere tests (detection and re-tests).
    std::uint64_t collisions = 0;     ///< Contacts resolved.
    std::uint64_t unresolved = 0;     ///< Particles still inside an ellipsoid after the re-test cap.
    Real max_penetration_m = 0;       ///< Deepest detected penetration, before response.
};

/// Optional record of detections (for tests): one bit set per particle of the ellipsoids
/// found to contain it at the start of the pass, before any response.
using DetectedPairs = std::vector<std::uint64_t>;

/// Steps 2-3 for particles [first, end) (end < 0: all). `candidates` null = brute force.
/// `last_collided` is read (tested first) and rewritten. A colliding particle keeps the
/// velocity it had before the push-out, less its approach toward each surface it touched
/// (relative to the surface's motion), its tangential part slowed by Coulomb `friction`.
/// `list_slack_m` (per particle; empty = unlimited): how far a particle may still move
/// before its list could miss an ellipsoid; a particle pushed farther is re-tested against
/// every ellipsoid. `respond_velocity` false: positions only. `above` (per particle; empty =
/// none): the particle above it on its warp line, itself in the first row; a particle the
/// re-tests cannot free may leave toward it (step 3). `listed` (empty = every particle of
/// the range): only these particles of [first, end), each tested on its own (for a few
/// scattered particles, cheaper than their blocks of 64).
CollisionResult collide_particles(Matrix3X& x, Matrix3X& v, const VectorX& inv_mass,
                                  std::span<const EllipsoidFrame> frames, const std::vector<std::uint64_t>* candidates,
                                  std::vector<std::uint64_t>& last_collided, DetectedPairs* detected = nullptr,
                                  Real friction = 0, std::span<const Real> list_slack_m = {}, Eigen::Index first = 0,
                                  Eigen::Index end = -1, bool respond_velocity = true,
                                  std::span<const std::uint32_t> above = {}, std::span<const std::uint32_t> listed = {});

/// Brute-force detection only (no response): bit set per particle of the ellipsoids containing it.
[[nodiscard]] DetectedPairs detect_brute_force(const Matrix3X& x, const VectorX& inv_mass,
                                               std::span<const EllipsoidFrame> frames);

/// Steps 2-3 for a garment's particles [first, end) in its collision mode against the
/// solver's frames (which must be current), with its material's friction; in list mode the
/// lists must be up to date (update_candidate_lists) or are brought up to date. Adds to the
/// garment's counters.
CollisionResult collide_range(Garment& garment, GarmentSolver& solver, Eigen::Index first, Eigen::Index end,
                              DetectedPairs* detected = nullptr, bool respond_velocity = true);

/// collide_range for positions `x` and velocities `v` of the garment's size, its counts added
/// to `counters` rather than the garment's (for parts running at the same time; the lists of
/// particles [first, end) must be up to date).
CollisionResult collide_part(const Garment& garment, GarmentSolver& solver, Matrix3X& x, Matrix3X& v,
                             Eigen::Index first, Eigen::Index end, bool respond_velocity, PartCounters& counters,
                             DetectedPairs* detected = nullptr);

/// The floor under the garments of `registry`: the highest GroundPlane's height, or -inf
/// with none.
[[nodiscard]] Real ground_height(const Registry& registry);

/// Moves the free particles [first, end) that lie below the floor y = ground_m straight up
/// onto it, adding each move to `push` when given (the substep's push-outs); returns how
/// many moved. Nothing moves when ground_m is -inf.
std::uint64_t collide_ground(Matrix3X& x, const VectorX& inv_mass, Real ground_m, Eigen::Index first, Eigen::Index end,
                             Matrix3X* push = nullptr);

/// Whether particle position `x` rests on the floor ground_m (on it or within 0.1 mm above:
/// a contact for the velocity update).
[[nodiscard]] inline bool on_ground(const Vec3& x, Real ground_m) noexcept { return x.y() <= ground_m + Real(1e-4); }

/// Whole garment: update_candidate_lists in list mode, then collide_range over every particle.
CollisionResult collide_garment(Garment& garment, GarmentSolver& solver, DetectedPairs* detected = nullptr);

}  // namespace drape
