// The garment's constraints in compliance form (method §3.3 springs, §4.1 Provot's limit),
// solved by Gauss-Seidel rounds after the explicit prediction of integrator.hpp.
//
// Step order of one round (cloth constraint system; docs/cloth.md "Solver"):
//   1. Springs, set by set in list order (warp springs run from the pins outward): the
//      stretch spring of stiffness k as an XPBD constraint of compliance 1/k (the implicit
//      response of the same Hooke spring, stable at any stiffness), then Provot's limit: a
//      spring still longer than (1 + limit) x rest has its ends moved back to the limit,
//      shared by inverse mass (a pinned end stays). With WarpSolve::lines the warp sets
//      are solved line by line instead (solve_lines), each line's springs at once.
//   2. Tethers: a free particle no farther from the pinned particle at the top of its warp
//      line than the rest length of the line between them (with WarpSolve::lines, that
//      times 1 + ClothMaterial::limit_share x limit; long-range attachments, as Jolt
//      and NvCloth hang cloth from its pins: a few Gauss-Seidel rounds cannot carry a long
//      line's weight up to its pin, the tether does it in one).
//   3. With a max distance (GarmentConfig::max_distance_share), each tethered particle back
//      within its sphere round its rest place carried by the anchor (solve_max_distance).
// After the rounds, once per substep, limit_warp_lines holds every warp spring within
// ClothMaterial::limit_share (half) of the limit by a one-sided pass from the pins down
// (follow the leader), then limit_weft_rows holds every weft row the same, each run of
// over-long springs solved as one chain.
// Positions only: the velocities follow from the whole substep's move afterwards
// (garment_step.hpp), as Provot's velocities follow his corrections.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "drape/components/garment.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// A run of `count` springs whose ends are consecutive particles: spring `first + k stride`
/// joins particles `a + k stride` and `b + k stride`, and no two springs of the run share a
/// particle, so the run is solved in vector lanes, each spring as if alone.
struct SpringStrip {
    std::uint32_t a = 0, b = 0, first = 0, count = 0;
    std::uint32_t stride = 1;
};

/// The strips of a phase in solving order. Springs listed in particle order (garment
/// builders) make long strips: a row of warp springs is a strip, solved row after row from
/// the fitting zone down; a chain of springs sharing ends is solved as its even springs,
/// then its odd ones; springs that fit no run become strips of one.
[[nodiscard]] std::vector<SpringStrip> spring_strips(const SpringPhase& springs);

/// A phase's strips cut by bands (systems/cloth/garment_parts.hpp).
struct BandStrips {
    std::vector<std::vector<SpringStrip>> parts;  ///< Per band, in solving order: the springs with both ends in it.
    std::vector<SpringStrip> edge;                ///< The springs joining two bands, one per strip.
};

/// `strips` cut where the band (per particle) of a lane's ends changes. One band gives the
/// strips as they are.
[[nodiscard]] BandStrips split_strips(const std::vector<SpringStrip>& strips, const std::vector<std::uint32_t>& band,
                                      std::size_t bands);

/// Springs of one phase as the solver sees them.
struct SpringSet {
    const SpringPhase* springs = nullptr;
    BandStrips strips;             ///< By the garment's bands (garment_parts.hpp).
    std::vector<Real> compliance;  ///< Per spring: 1 / k, m/N (1e30: a spring without force).
    std::vector<Real> lambda;      ///< Per spring: XPBD multiplier of the current substep.
    bool limited = true;           ///< Provot's limit applies (structural springs).
    /// Warp lines solved directly (solve_lines; see line_chains): per spring the springs
    /// above and below it on its line (no_spring: none), per band and strip whether the
    /// strips before and after it hold those one lane to one lane, and the chain solve's
    /// scratch. Empty `next`: Gauss-Seidel strips (solve_springs).
    std::vector<std::uint32_t> prev, next;
    std::vector<std::vector<std::uint8_t>> aligned_prev, aligned_next;
    std::vector<Real> dir0, dir1, dir2, offdiag, pivot, rhs;
};

inline constexpr std::uint32_t no_spring = 0xffffffffu;

/// Sets `set` (a warp phase, its strips made) up for solve_lines: the springs above and
/// below each spring on its line. Returns false, leaving it to the Gauss-Seidel strips,
/// when a band's strips do not run from the pins down (a spring before the one above it).
bool line_chains(SpringSet& set);

/// One round over band `band` of a warp set solved along its lines (line_chains; instead
/// of solve_springs): each line's springs are one chain whose XPBD constraints, linearised
/// at the current positions, are solved at once, a tridiagonal system per line (Thomas),
/// so that a round hangs a line at the stretch its modulus gives, however long the line
/// and stiff the cloth. The linearisation is a Newton step: a line bent over the hips or
/// zigzagging needs several, so the solve is repeated at the new positions while a spring's
/// right-hand side over its rest length exceeds `tolerance`, at most `max_iterations` times
/// (at least once). The multipliers accumulate over the substep's rounds as in
/// solve_springs. Provot's limit is left to the warp limit after the rounds. Returns the
/// Newton steps taken.
int solve_lines(SpringSet& set, std::size_t band, Matrix3XRows& x, const VectorX& inv_mass, Real h_s,
                int max_iterations = 1, Real tolerance = 0);

/// Per spring: 1 / k with k = modulus x (area_a + area_b) / (2 rest^2) (components/garment.hpp).
/// `area` per particle; a modulus of 0 gives a spring without force (limit only).
[[nodiscard]] std::vector<Real> spring_compliance(const SpringPhase& springs, const VectorX& area, Real modulus_N_m);

/// One Gauss-Seidel round over band `band` of `set` (step 1) in a substep of h_s, strip by
/// strip, on positions held one row per coordinate. `inv_mass` 0 = does not move.
void solve_springs(SpringSet& set, std::size_t band, Matrix3XRows& x, const VectorX& inv_mass, Real h_s, Real limit);

/// The same for the springs of `set` that join two bands, on positions held one column per
/// particle or one row per coordinate (the same arithmetic).
void solve_edge_springs(SpringSet& set, Matrix3X& x, const VectorX& inv_mass, Real h_s, Real limit);
void solve_edge_springs(SpringSet& set, Matrix3XRows& x, const VectorX& inv_mass, Real h_s, Real limit);

/// Long-range attachments (step 2): one per free particle below a pinned one on its line.
struct Tethers {
    std::vector<std::uint32_t> particle;  ///< The free particle.
    std::vector<std::uint32_t> anchor;    ///< The pinned particle above it on its warp line.
    std::vector<Real> length_m;           ///< Rest length of the line between them.
};

/// Per particle: rest length of the warp spring to the particle above it on its line (0 in
/// the first row).
[[nodiscard]] VectorX warp_rest_above(const Fabric& fabric);

/// Tethers of every free particle, layer 2 included, from the nearest pinned particle above
/// it on its warp line; none for a line without a pinned particle. `rest_above`:
/// warp_rest_above(fabric).
[[nodiscard]] Tethers build_tethers(const Fabric& fabric, const VectorX& inv_mass, const VectorX& rest_above);

/// The tethers of each band: those whose particle is in band k (order kept).
[[nodiscard]] std::vector<Tethers> split_tethers(const Tethers& tethers, const std::vector<std::uint32_t>& band,
                                                 std::size_t bands);

/// One pass over the tethers (step 2).
void solve_tethers(const Tethers& tethers, Matrix3XRows& x);

/// The max distance (GarmentConfig::max_distance_share > 0; step 3, after the tethers): each
/// tethered particle stays within `share` x its tether's length of its place in the rest
/// shape carried by the anchor, `anchor * rest_local.col(p)` (as Unity Cloth's max distance
/// and NvCloth's motion constraints keep a particle within a sphere round its skinned
/// place): a particle outside that sphere is moved onto it. At share 1 the hem may swing
/// 60 degrees from where it hangs at rest, but not up past its pins. `rest_local` holds a
/// column per particle of `x` (or none: nothing is done).
void solve_max_distance(const Tethers& tethers, const Matrix3X& rest_local, const Affine3& anchor, Real share,
                        Matrix3XRows& x);

/// The same with each sphere's centre given per particle (GarmentConfig::max_distance_on_skin):
/// `(1 - alpha) previous.col(p) + alpha target.col(p)`, the centres at the start and the end of
/// the fixed step and the substep's share of it, lowered to the anchor's centre
/// `anchor * rest_local.col(p)` where higher (world y): a leg carries its spheres forward
/// and back, not up.
void solve_max_distance(const Tethers& tethers, const Matrix3X& previous, const Matrix3X& target, Real alpha,
                        const Matrix3X& rest_local, const Affine3& anchor, Real share, Matrix3XRows& x);

/// After the rounds: the warp limit (Provot's rule for a fixed end, method §4.1). Row after
/// row from the fitting zone down, a free particle farther than (1 + stretch) x rest from
/// the particle above it on its line is moved back onto that sphere, the particle above
/// staying where it is (it already has its final place), so no warp spring is longer than
/// that afterwards. `moves` receives each particle's move (zero for the rest). Lines
/// [first_line, end_line) only; the lines are independent of each other. Returns the
/// particles moved.
std::uint64_t limit_warp_lines(const Fabric& fabric, const VectorX& rest_above, const VectorX& inv_mass, Real stretch,
                      Matrix3X& x, Matrix3X& moves, std::uint32_t first_line, std::uint32_t end_line);

/// Provot's limit as Provot gives it (method §4.1), for the paper's integrator: one
/// Gauss-Seidel pass over `springs` in their order; a spring longer than (1 + limit) x rest
/// has its ends moved toward each other back to that length, half each when both are free,
/// only the free one when the other is pinned (`inv_mass` 0). Returns the springs corrected.
std::uint64_t provot_pass(const SpringPhase& springs, const VectorX& inv_mass, Real limit, Matrix3X& x);

/// Per particle: rest length of the weft spring to its neighbour on the next line (0 for
/// none).
[[nodiscard]] VectorX weft_rest_right(const Fabric& fabric);

/// Passes of limit_weft_rows, and how far over its bound (a share of the rest length) a
/// spring must be for a pass to act on its row.
inline constexpr int weft_limit_passes = 3;
inline constexpr Real weft_limit_tolerance = Real(0.01);

/// What limit_weft_rows works in, per weft spring of a row (sized on each call; keeping one
/// per thread spares the allocations).
struct WeftLimitScratch {
    std::vector<std::uint32_t> p;
    std::vector<Vec3> dir;
    std::vector<Real> excess, diag, upper, dl, sweep;
    std::vector<char> dirty;
};

/// After the rounds, with the warp limit: Provot's limit along every weft row [first_row,
/// end_row) at once (an extension of method §4.1). Where a spring of a row is longer than
/// (1 + stretch) x rest by more than weft_limit_tolerance x rest, every run of neighbouring
/// springs over (1 + stretch) x rest is brought back to that length together, as one chain:
/// the run's linearised constraints, a tridiagonal system, solved directly, its moves
/// shared by inverse mass (a pinned end stays). A few passes (weft_limit_passes) take up
/// what the linearisation leaves. Rows are independent of each other. `moves` receives
/// each particle of the rows' move (zero for the rest). Returns the spring corrections made.
/// `scratch` null: a local one.
std::uint64_t limit_weft_rows(const Fabric& fabric, const VectorX& rest_right, const VectorX& inv_mass, Real stretch,
                              Matrix3X& x, Matrix3X& moves, std::uint32_t first_row, std::uint32_t end_row,
                              WeftLimitScratch* scratch = nullptr);

/// The same on the rows listed, in their order.
std::uint64_t limit_weft_rows(const Fabric& fabric, const VectorX& rest_right, const VectorX& inv_mass, Real stretch,
                              Matrix3X& x, Matrix3X& moves, std::span<const std::uint32_t> rows,
                              WeftLimitScratch* scratch = nullptr);

}  // namespace drape
