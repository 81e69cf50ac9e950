// A garment on a body that does not move comes to rest: the constraints, the layer-2
// carriage, the warp limit and the collision response must not keep feeding each other
// energy.
#include <gtest/gtest.h>

#include <algorithm>

#include "analytic_body.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
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

}  // namespace
}  // namespace drape
