// Provot's dynamic inverse constraints (method §4.1, §4.2 item 3; Provot 1995).
//
// Step order of one call:
//   1. `iterations` symmetric passes: a spring longer than (1 + limit) x rest has its ends
//      moved toward each other by the excess, half each; an end that may not move (pinned,
//      or a layer-1 particle while the weft is corrected) stays and the other takes all.
//   2. Optionally one ordered pass in list order, moving only the far end (`b`) when it may
//      move. Warp springs are listed from the fitting zone outward, so after this pass no
//      warp spring exceeds the limit: each particle is moved once, after the spring above it.
// A particle with a plane (non-zero column of `plane_normal`, layer 2, method §4.2 item 1)
// is moved only within its plane; in the ordered pass its in-plane offset is rescaled so
// that the spring ends exactly at the limit.
// Every move dx also changes the particle's velocity by dx / h (Provot: velocities follow).
#pragma once

#include <cstdint>
#include <span>

#include "components/garment.hpp"
#include "engine/core/math.hpp"

namespace drape {

struct StrainLimitOptions {
    Real limit = Real(0.10);           ///< Max relative over-stretch.
    int iterations = 2;                ///< Symmetric passes.
    bool ordered_pass = true;          ///< Finish with the ordered pass (warp springs).
    Real h_s = 0;                      ///< Substep length for the velocity correction; 0 = positions only.
    const Matrix3X* plane_normal = nullptr;  ///< Per particle unit plane normal, or zero; null = no planes.
};

/// Applies Provot's correction to `springs`; `movable[i]` != 0 when particle i may move.
void limit_strain(const SpringPhase& springs, Matrix3X& x, Matrix3X& v, std::span<const std::uint8_t> movable,
                  const StrainLimitOptions& options);

/// Largest length / rest - 1 over `springs` (0 when none is stretched).
[[nodiscard]] Real max_strain(const SpringPhase& springs, const Matrix3X& x);

}  // namespace drape
