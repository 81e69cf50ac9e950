// The after-frame contract asked of a garment on a character the team did not tune for (the
// shared third-party characters, the generator's unusual builds): strain p99 <= 10 %, max
// <= 20 %, nothing left inside after the frame beyond 2 mm, pins outside, nothing
// non-finite, no reset. In a labelled test's short form (tests/figures.hpp) only what a
// short run shows in any build: nothing non-finite.
#pragma once

#include <gtest/gtest.h>

#include "drape/game/stats.hpp"
#include "tests/figures.hpp"

namespace drape::test {

inline void expect_character_contract(const GarmentStats& g) {
    EXPECT_EQ(g.nonfinite, 0u);
    if (short_form()) return;
    EXPECT_LE(g.strain_p99, 0.10);
    EXPECT_LE(g.strain_max, 0.20);
    EXPECT_LE(g.penetration_after_frame_m, 2e-3);
    EXPECT_LE(g.pins_inside_m, 5e-3);
    EXPECT_EQ(g.resets, 0u);
}

}  // namespace drape::test
