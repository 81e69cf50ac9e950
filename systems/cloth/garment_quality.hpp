// What a user sees of a garment after a whole frame, measured (the quality contract of
// docs/cloth.md): strain of the structural springs, particles left inside the body, pinned
// particles inside the colliders, particles flung above the pins, non-finite values.
//
// Conventions
// - Strain of a spring: length / rest - 1 (compression counts as 0), over every structural
//   spring (warp of both layers, weft) with at least one free end: between two pinned
//   particles the skin decides. Compression is reported apart: the shortest of those springs
//   over its rest length; so is the pinned rows' own strain, of the springs between two
//   pinned particles, which the skinning of the pins and their push-out give (a fitting zone
//   the skin tears is seen, though the cloth cannot mend it).
// - Depth inside an ellipsoid: how far the centre-line response would move the particle out
//   (collision.hpp penetration_depth), an upper bound of its distance to the surface; for an
//   ellipsoid that gives (EllipsoidCollider::give_m), the depth past what its give allows
//   there (depth_past_give), the depth within the give reported apart.
// - Below the floor: how far a free particle lies under the GroundPlane's height.
// - Rise above the pins: the largest height of a free particle above the highest pinned
//   particle, along the body's up (body_up): the direction from the garment's free
//   particles to its pins in its rest shape, carried by the anchor's rotation, so that a
//   body lying down (a fall, a death) or bent over (sitting) is measured as it stands; 0 when
//   none is higher.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "drape/components/garment.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/cloth/garment_solver.hpp"

namespace drape {

/// The body's up for the rise above the pins: from the mean of the garment's free particles
/// to the mean of its pinned ones in its rest shape (GarmentBody::rest_local), turned by
/// the anchor's rotation among `frames`. World up (+Y) without an anchor or pins.
[[nodiscard]] Vec3 body_up(const Garment& garment, std::span<const EllipsoidFrame> frames);

/// One garment after one frame.
struct GarmentQuality {
    Real strain_max = 0;            ///< Largest strain of a spring with a free end.
    Real strain_p99 = 0;            ///< Its 99th percentile over those springs.
    Real compression_min = 1;       ///< Shortest of those springs over its rest length (1: none shorter than rest).
    Real pinned_strain_max = 0;     ///< Largest strain of a spring between two pinned particles (not in strain_max).
    Real penetration_m = 0;         ///< Deepest free particle inside an ellipsoid (past its give).
    Real within_give_m = 0;         ///< Deepest free particle inside an ellipsoid within its give.
    Real pins_inside_m = 0;         ///< Deepest pinned particle inside an ellipsoid.
    Real below_ground_m = 0;        ///< Deepest free particle below the floor (components/ground_plane.hpp).
    Real rise_above_pins_m = 0;     ///< See the conventions above.
    std::uint64_t nonfinite = 0;    ///< Non-finite coordinates in x and v.
    std::uint64_t springs = 0;      ///< Springs measured.
    std::uint32_t worst_a = 0;      ///< The spring of strain_max: its end nearer the pins (warp) or before it round the
    std::uint32_t worst_b = 0;      ///< ring (weft), and its other end; equal when no spring was measured.
};

/// Where a spring lies on the garment and on the body: what a tear is caught on. The body
/// part is the ellipsoid nearest the spring's middle in unit-sphere terms (the measure the
/// pins are bound by); the spring straddles it when its chord passes through it (its middle
/// inside) with its two ends on sides of it more than 60 degrees apart, seen from its centre
/// in unit-sphere terms, which a spring lying over a surface shows only where the surface
/// bends tighter than the spring is long: a piece thinner than the cloth's spacing holding
/// two neighbours apart.
struct SpringPlace {
    bool weft = false;              ///< A weft spring (round the body), else a warp spring (down a line).
    std::uint32_t line = 0;         ///< Warp line of its first end.
    std::uint32_t row = 0;          ///< Row of its first end, 0 at the fitting zone.
    std::uint32_t rows = 0;         ///< Rows of the garment (particles per line).
    std::int32_t collider = -1;     ///< Nearest ellipsoid: index into the frames (GarmentBody::colliders); -1: none.
    Real thickness_m = 0;           ///< That ellipsoid's smallest radius.
    Real unit_distance = 0;         ///< The spring's middle from its centre in unit-sphere terms (1: on its surface).
    bool straddles = false;         ///< See above.
};

/// Where the spring between particles `a` and `b` lies, against `frames` (the colliders as
/// the cloth sees them).
[[nodiscard]] SpringPlace place_spring(const Garment& garment, std::span<const EllipsoidFrame> frames, std::uint32_t a,
                                       std::uint32_t b);

/// Strain histogram over many frames, for percentiles of a whole run (bins of 0.1 %).
class StrainHistogram {
public:
    static constexpr Real bin = Real(0.001);
    static constexpr std::size_t bins = 4000;  ///< Up to 400 %; beyond, the last bin.
    void add(Real strain) noexcept;
    /// Every strain of `strains`, as add() one by one.
    void add(std::span<const Real> strains) noexcept;
    /// Strain below which a share `q` of the samples lie (upper edge of the bin).
    [[nodiscard]] Real percentile(double q) const noexcept;
    [[nodiscard]] std::uint64_t samples() const noexcept { return m_samples; }

private:
    std::array<std::uint64_t, bins> m_counts{};
    std::uint64_t m_samples = 0;
};

/// Mean horizontal distance of the hem (each warp line's last particle) from the centre of
/// the fitting row (row 0), m: how far a garment keeps its cut. `grid_order`: the columns of
/// `x` are line * m + row (Fabric::rest_shape), else particles (GarmentState::x).
[[nodiscard]] double hem_radius_m(const Fabric& fabric, const Matrix3X& x, bool grid_order);

/// Kinetic energy of particles with masses 1 / inv_mass (pinned ones, inv_mass 0, left out), J.
[[nodiscard]] double kinetic_energy_J(const Matrix3X& v, const VectorX& inv_mass);

/// Measures `garment` against `frames` (the colliders as the cloth sees them, e.g. the
/// solver's frames at the end of the step) and the floor `ground_m` (-inf: none). When
/// `histogram` is given, every measured spring's strain is added to it.
[[nodiscard]] GarmentQuality measure_garment(const Garment& garment, std::span<const EllipsoidFrame> frames,
                                             StrainHistogram* histogram = nullptr,
                                             Real ground_m = -std::numeric_limits<Real>::infinity());

/// The same with the colliders read from the registry at their current pose, and its floor.
[[nodiscard]] GarmentQuality measure_garment(const Registry& registry, const Garment& garment,
                                             StrainHistogram* histogram = nullptr);

}  // namespace drape
