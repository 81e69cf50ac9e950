// What `drape bench stability` judges a run by, as functions of plain data (tests call them
// without a world): divergence (the simulation ran away) apart from quality (how well the
// garment held: strain and penetration, measured by systems/cloth/garment_quality.hpp).
//
// A run diverged when
//   - a coordinate went non-finite (the cloth resets such a garment and counts it);
//   - a particle is farther from its pin (the nearest along the springs) than (1 + reach_factor)
//     x its line's rest length, the longest rest-length path from that pin: how far the garment
//     reaches from there (for a skirt, the warp line from the waist to the hem);
//   - its kinetic energy grew: the peak of the last third of the run is above energy_growth x
//     the peak of the first two thirds, and above energy_floor_J.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "bench/probe.hpp"
#include "drape/engine/core/math.hpp"

namespace drape::bench {

/// Per particle: the pinned particle nearest along the springs, the rest length of that path
/// (Dijkstra over `springs` from every pinned particle), and its line's rest length: the
/// longest such path from the same pin. Pinned particles: themselves, 0. A particle no spring
/// path joins to a pin: `no_pin`, +inf.
struct PinReach {
    static constexpr std::uint32_t no_pin = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> pin;
    std::vector<double> rest_m;
    std::vector<double> line_m;
};
[[nodiscard]] PinReach pin_reach(std::size_t particles, const StructuralSprings& springs,
                                 const std::vector<std::uint32_t>& pinned);

/// Largest |x_p - x_pin(p)| / line_m(p) over the free particles joined to a pin; +inf when such
/// a particle is not finite, 0 when there is none.
[[nodiscard]] double worst_reach_ratio(const Matrix3X& x, const PinReach& reach);

/// Thresholds of the divergence test.
struct DivergenceLimits {
    double reach_factor = 1.0;   ///< A particle beyond (1 + this) x its line's rest length from its pin.
    double energy_growth = 10;   ///< Peak of the last third over the peak of the first two thirds.
    double energy_floor_J = 0;   ///< Energy growth only counts above this.
};

/// What a run did, frame by frame, as the divergence test reads it.
struct RunTrace {
    std::uint64_t non_finite_values = 0;    ///< Non-finite coordinates found during the run.
    int first_non_finite_frame = -1;
    std::vector<double> energy_J;           ///< Kinetic energy after each frame.
    double worst_reach_ratio = 0;           ///< Largest worst_reach_ratio after any frame.
    int worst_reach_frame = -1;
    std::string frame_word = "frame";       ///< What the reasons call a frame ("step" for a bare integrator).
};

struct Divergence {
    bool diverged = false;
    std::string reason;   ///< The first test that tripped (non-finite, reach, energy); empty when none.
};

[[nodiscard]] Divergence classify_divergence(const RunTrace& trace, const DivergenceLimits& limits);

}  // namespace drape::bench
