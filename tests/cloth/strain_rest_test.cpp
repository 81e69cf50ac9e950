// A garment on a body that does not move comes to rest: the strain limit, the layer-2
// placement and the collision response must not keep feeding each other energy.
#include <gtest/gtest.h>

#include "analytic_body.hpp"
#include "systems/cloth/garment_builder.hpp"
#include "systems/cloth/garment_step.hpp"
#include "systems/cloth/substeps.hpp"

namespace drape {
namespace {

TEST(StrainRest, SkirtOnAStillBodyComesToRest) {
    Registry registry;
    test::AnalyticBody body(registry);
    const Entity e = *attach_skirt(registry, body.character, SkirtParams{});
    Garment& g = registry.get<Garment>(e);
    const double dt = 1.0 / 60.0;
    double mean_speed = 0;
    const int frames = 600, measured = 60;
    for (int frame = 0; frame < frames; ++frame) {
        body.place(registry, 0, false, dt);  // the pose of t = 0, held
        const int substeps = garment_substeps(registry, g, dt, ClothSolverSettings{});
        FrameContext ctx;
        ctx.fixed_dt_s = dt;
        ctx.substeps = substeps;
        ctx.h_s = dt / substeps;
        for (int s = 0; s < substeps; ++s) {
            ctx.substep = s;
            integrate_garment(registry, g, ctx);
            constrain_garment(g, ctx);
            collide_garment_step(registry, g, ctx);
        }
        if (frame < frames - measured) continue;
        double sum = 0;
        int free = 0;
        for (Eigen::Index p = 0; p < g.x.cols(); ++p)
            if (g.inv_mass[p] > 0) {
                sum += g.v.col(p).norm();
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
