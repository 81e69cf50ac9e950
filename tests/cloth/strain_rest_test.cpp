// A garment on a body that does not move comes to rest: the constraints, the layer-2
// carriage, the warp limit and the collision response must not keep feeding each other
// energy.
#include <gtest/gtest.h>

#include "analytic_body.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_step.hpp"

namespace drape {
namespace {

TEST(StrainRest, SkirtOnAStillBodyComesToRest) {
    Registry registry;
    test::AnalyticBody body(registry);
    const Entity e = *attach_skirt(registry, body.character, TubeParams::skirt());
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& solver = registry.get<GarmentSolver>(e);
    double mean_speed = 0;
    const int frames = 600, measured = 60;
    for (int frame = 0; frame < frames; ++frame) {
        test::step_by_hand(body, registry, g, solver, 1, test::StageCheck{}, test::StageCheck{}, /*hold_pose=*/true);
        if (frame < frames - measured) continue;
        // After the whole frame: the velocities the next frame starts from.
        double sum = 0;
        int free = 0;
        for (Eigen::Index p = 0; p < g.state.x.cols(); ++p)
            if (g.state.inv_mass[p] > 0) {
                sum += g.state.v.col(p).norm();
                ++free;
            }
        mean_speed += sum / free / measured;
    }
    EXPECT_EQ(g.counters.resets, 0u);
    // After 9 s the skirt hangs still: mean particle speed under 1 cm/s.
    EXPECT_LT(mean_speed, 0.01);
    RecordProperty("mean_speed_m_s", std::to_string(mean_speed));
}

}  // namespace
}  // namespace drape
