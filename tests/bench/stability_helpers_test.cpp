// What `drape bench stability` calls divergence: pin reach along the springs, the reach
// ratio, energy growth and non-finite values, each on data with a known answer.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "bench/stability_bench.hpp"
#include "drape/systems/cloth/garment_quality.hpp"

namespace drape::bench {
namespace {

/// A chain 0 - 1 - 2 - 3 with rest lengths 0.1, 0.2, 0.3, and particle 4 joined to nothing.
StructuralSprings chain_springs() {
    StructuralSprings s;
    s.springs = {{0, 1}, {1, 2}, {2, 3}};
    s.rest_m = {0.1f, 0.2f, 0.3f};
    return s;
}

TEST(StabilityPinReach, RestLengthPathToTheNearestPin) {
    const PinReach r = pin_reach(5, chain_springs(), {0, 3});
    EXPECT_EQ(r.pin[0], 0u);
    EXPECT_DOUBLE_EQ(r.rest_m[0], 0);
    EXPECT_EQ(r.pin[1], 0u);
    EXPECT_NEAR(r.rest_m[1], 0.1, 1e-6);
    // Particle 2: 0.3 m from pin 0 along the chain, 0.3 m from pin 3; either pin, 0.3 m.
    EXPECT_NEAR(r.rest_m[2], 0.3, 1e-6);
    EXPECT_EQ(r.pin[3], 3u);
    EXPECT_EQ(r.pin[4], PinReach::no_pin);
    EXPECT_TRUE(std::isinf(r.rest_m[4]));
}

TEST(StabilityPinReach, TakesTheShorterOfTwoPaths) {
    StructuralSprings s = chain_springs();
    s.springs.push_back({0, 3});   // a shortcut from the pin to the end
    s.rest_m.push_back(0.05f);
    const PinReach r = pin_reach(4, s, {0});
    EXPECT_NEAR(r.rest_m[3], 0.05, 1e-6);
    EXPECT_NEAR(r.rest_m[2], 0.3, 1e-6);   // 0.1 + 0.2 beats 0.05 + 0.3
}

TEST(StabilityPinReach, LineIsTheLongestPathFromTheSamePin) {
    StructuralSprings s;
    s.springs = {{0, 1}, {1, 2}, {3, 4}};
    s.rest_m = {0.1f, 0.2f, 0.5f};
    const PinReach r = pin_reach(5, s, {0, 3});
    for (int p : {0, 1, 2}) EXPECT_NEAR(r.line_m[static_cast<std::size_t>(p)], 0.3, 1e-6) << p;
    for (int p : {3, 4}) EXPECT_NEAR(r.line_m[static_cast<std::size_t>(p)], 0.5, 1e-6) << p;
}

TEST(StabilityReachRatio, DistanceToThePinOverTheLineRestLength) {
    const PinReach r = pin_reach(4, chain_springs(), {0});
    Matrix3X x(3, 4);
    x << 0, 0.1f, 0.3f, 0.6f,  // straight, at rest: the hem is one line length from the pin
        0, 0, 0, 0,            //
        0, 0, 0, 0;
    EXPECT_NEAR(worst_reach_ratio(x, r), 1.0, 1e-5);
    x(0, 1) = 0.5f;   // the first spring 5x its rest length, still within the line's reach
    EXPECT_NEAR(worst_reach_ratio(x, r), 1.0, 1e-5);
    x(0, 3) = 1.8f;   // 1.8 m from the pin, line 0.6 m
    EXPECT_NEAR(worst_reach_ratio(x, r), 3.0, 1e-5);
    x(1, 2) = std::numeric_limits<Real>::quiet_NaN();
    EXPECT_TRUE(std::isinf(worst_reach_ratio(x, r)));
}

TEST(StabilityDivergence, QuietRunDidNotDiverge) {
    RunTrace t;
    t.energy_J = {1, 2, 1.5, 1, 0.8, 0.9};
    t.worst_reach_ratio = 1.1;
    const Divergence d = classify_divergence(t, {});
    EXPECT_FALSE(d.diverged);
    EXPECT_TRUE(d.reason.empty());
}

TEST(StabilityDivergence, NonFiniteValuesComeFirst) {
    RunTrace t;
    t.non_finite_values = 3;
    t.first_non_finite_frame = 7;
    t.worst_reach_ratio = 50;
    const Divergence d = classify_divergence(t, {});
    EXPECT_TRUE(d.diverged);
    EXPECT_NE(d.reason.find("non-finite"), std::string::npos);
    EXPECT_NE(d.reason.find("frame 7"), std::string::npos);
}

TEST(StabilityDivergence, BeyondTheReachOfItsPin) {
    RunTrace t;
    t.worst_reach_ratio = 2.5;
    t.worst_reach_frame = 4;
    DivergenceLimits limits;
    limits.reach_factor = 1.0;
    const Divergence d = classify_divergence(t, limits);
    EXPECT_TRUE(d.diverged);
    EXPECT_NE(d.reason.find("2.50x"), std::string::npos);
    t.worst_reach_ratio = 1.9;   // stretched 90 % on average: a bad cloth, not a runaway one
    EXPECT_FALSE(classify_divergence(t, limits).diverged);
}

TEST(StabilityDivergence, EnergyGrowthInTheLastThirdAgainstAllBefore) {
    DivergenceLimits limits;
    limits.energy_growth = 10;
    limits.energy_floor_J = 0.5;
    RunTrace t;
    t.energy_J = {3, 0.1, 0.1, 0.1, 0.1, 0.1, 0.2, 5, 8};
    // The last third peaks at 8 J: above 10x the middle third (0.1 J) but not 10x the first
    // third's 3 J: no growth over the whole run so far.
    EXPECT_FALSE(classify_divergence(t, limits).diverged);
    t.energy_J[0] = 0.1;
    const Divergence d = classify_divergence(t, limits);
    EXPECT_TRUE(d.diverged);
    EXPECT_NE(d.reason.find("energy"), std::string::npos);
    // Below the floor, growth does not count.
    t.energy_J = {0.001, 0.001, 0.001, 0.001, 0.001, 0.001, 0.1, 0.2, 0.3};
    EXPECT_FALSE(classify_divergence(t, limits).diverged);
}

TEST(StabilityDivergence, KineticEnergyLeavesPinnedParticlesOut) {
    Matrix3X v(3, 2);
    v << 2, 5, 0, 0, 0, 0;
    VectorX inv_mass(2);
    inv_mass << 0.5f, 0;   // 2 kg at 2 m/s; the pinned one moves but has no mass here
    EXPECT_NEAR(kinetic_energy_J(v, inv_mass), 4.0, 1e-6);
}

}  // namespace
}  // namespace drape::bench
