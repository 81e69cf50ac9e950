// A garment on a body that does not move comes to rest: the constraints, the layer-2
// carriage, the warp limit and the collision response must not keep feeding each other
// energy.
#include <gtest/gtest.h>

#include <algorithm>

#include "analytic_body.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_config.hpp"
#include "drape/systems/cloth/garment_quality.hpp"
#include "drape/systems/cloth/garment_step.hpp"

namespace drape {
namespace {

// A skirt on a body held still comes to rest: over the last second of ten, its particles
// stop moving (positions, not the stored velocities the next step starts from: a particle
// can keep a velocity that the constraints and the collision take back every step).
TEST(StrainRest, SkirtOnAStillBodyComesToRest) {
    Registry registry;
    test::AnalyticBody body(registry);
    const Entity e = *attach_skirt(registry, body.character, TubeParams::skirt());
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& solver = registry.get<GarmentSolver>(e);
    const int frames = 600, measured = 60;
    Matrix3X before;
    Real largest_move = 0;  // of a free particle over one frame, in the last second
    for (int frame = 0; frame < frames; ++frame) {
        before = g.state.x;
        test::step_by_hand(body, registry, g, solver, 1, test::StageCheck{}, test::StageCheck{}, /*hold_pose=*/true);
        if (frame < frames - measured) continue;
        for (Eigen::Index p = 0; p < g.state.x.cols(); ++p)
            if (g.state.inv_mass[p] > 0) largest_move = std::max(largest_move, (g.state.x.col(p) - before.col(p)).norm());
    }
    EXPECT_EQ(g.counters.resets, 0u);
    // After 9 s the skirt hangs still: no free particle moves 0.1 mm in a frame (6 mm/s).
    EXPECT_LT(largest_move, Real(1e-4));
    RecordProperty("largest_move_m", std::to_string(largest_move));
}

// The warp and weft limits hold a spring within limit_share x Provot's limit each substep
// (ClothMaterial::limit_share): on a still body the skirt's hanging lines stop at half the
// limit by default (p99 5.0 % after 2 s); with the whole limit theirs they hang longer (5.7 %),
// never past Provot's 10 %.
TEST(StrainRest, TheLimitsHoldTheSpringsWithinTheirShareOfProvotsLimit) {
    const auto hanging_p99 = [](Real share) {
        Registry registry;
        test::AnalyticBody body(registry);
        const Entity e = *attach_skirt(registry, body.character, TubeParams::skirt());
        ClothMaterial material = registry.get<Garment>(e).config.material;
        material.limit_share = share;
        EXPECT_TRUE(set_garment_material(registry, e, material));
        Garment& g = registry.get<Garment>(e);
        GarmentSolver& solver = registry.get<GarmentSolver>(e);
        for (int frame = 0; frame < 120; ++frame)
            test::step_by_hand(body, registry, g, solver, 1, test::StageCheck{}, test::StageCheck{}, /*hold_pose=*/true);
        return measure_garment(registry, g).strain_p99;
    };
    const Real limit = ClothMaterial{}.strain_limit;
    const Real half = hanging_p99(Real(0.5)), whole = hanging_p99(Real(1));
    RecordProperty("p99_at_half", std::to_string(half));
    RecordProperty("p99_at_whole", std::to_string(whole));
    EXPECT_LE(half, Real(0.5) * limit * Real(1.01));
    EXPECT_GT(whole, Real(0.5) * limit * Real(1.05));
    EXPECT_LE(whole, limit);
}

}  // namespace
}  // namespace drape
