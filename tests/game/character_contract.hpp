// The after-frame contract asked of a garment on a character the team did not tune for (the
// shared third-party characters, the generator's unusual builds): strain p99 <= 10 %, max
// <= 20 %, no spring shorter than 25 % of its rest length, nothing left inside after the
// frame beyond 2 mm, pins outside, nothing non-finite, no reset. In a labelled test's short
// form (tests/figures.hpp) only what a short run shows in any build: nothing non-finite.
#pragma once

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "drape/game/stats.hpp"
#include "tests/figures.hpp"
#include "tests/test_paths.hpp"

namespace drape::test {

/// The build's machine flags and this CPU: a chaotic run lands elsewhere when either differs
/// from where its figures were measured (docs/cloth.md "Reproducibility"), so a failure says
/// which it ran on.
inline std::string machine() {
    std::string cpu = "unknown CPU";
    std::ifstream info("/proc/cpuinfo");
    for (std::string line; std::getline(info, line);)
        if (line.rfind("model name", 0) == 0) {
            cpu = line.substr(line.find(':') + 2);
            break;
        }
    return std::string("built with '") + test::machine_flags() + "', run on " + cpu;
}

inline void expect_character_contract(const GarmentStats& g) {
    SCOPED_TRACE(machine());
    EXPECT_EQ(g.nonfinite, 0u);
    if (short_form()) return;
    EXPECT_LE(g.strain_p99, 0.10);
    EXPECT_LE(g.strain_max, 0.20);
    EXPECT_GE(g.compression_min, 0.25);
    EXPECT_LE(g.penetration_after_frame_m, 2e-3);
    EXPECT_LE(g.pins_inside_m, 5e-3);
    EXPECT_EQ(g.resets, 0u);
}

}  // namespace drape::test
