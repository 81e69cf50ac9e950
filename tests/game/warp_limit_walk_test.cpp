// The warp bound of the constraint system (method §4.1, §4.2; docs/cloth.md "Per substep") on
// the default avatar walking in place, the world built as `drape play` builds it and the
// cloth stepped by hand so that the springs are measured right after the constraint system:
// every warp spring with at least one free end, layer 1 and layer 2, those hanging from the
// fitting zone included (the waistband follows the skin around the hips, up to a few cm off
// the chords below it), is at most 1.10 x rest. Free layer-2 particles lie on their planes.
#include <gtest/gtest.h>

#include <filesystem>

#include "game/asset_paths.hpp"
#include "game/sample_scene.hpp"
#include "game/world.hpp"
#include "systems/cloth/garment_step.hpp"
#include "systems/cloth/weft.hpp"

namespace drape {
namespace {

struct WalkCase {
    GarmentType garment;
    ClothModel model;
    int frames;
};

class WarpLimitOnTheWalkingAvatar : public ::testing::TestWithParam<WalkCase> {};

TEST_P(WarpLimitOnTheWalkingAvatar, EveryWarpSpringWithAFreeEndIsWithinTenPercentAfterTheConstraintSystem) {
    const WalkCase c = GetParam();
    SceneDescription scene = sample_scene();
    if (scene.characters.empty() || !std::filesystem::exists(default_avatar_path()))
        GTEST_SKIP() << "the default avatar (assets/avatar.glb) is not available";
    scene.characters.resize(1);
    scene.garments.resize(1);
    scene.garments[0].type = c.garment;
    scene.garments[0].model = c.model;
    scene.garments[0].character = 0;
    WorldOptions options;
    options.profile = false;
    auto world = build_world(scene, options);
    ASSERT_TRUE(world) << world.error().message;
    Garment& g = world->registry.get<Garment>(world->garments.at(0));
    const Fabric& t = *g.fabric;
    const bool simplified = c.model == ClothModel::simplified;
    Matrix3X normals(3, t.layer1_count);

    GarmentSolver& solver = world->registry.get<GarmentSolver>(world->garments.at(0));
    const double dt = 1.0 / 60.0;
    std::size_t below_pins = 0, on_planes = 0;
    StepHooks hooks;
    int frame = 0;
    hooks.after_constraints = [&](Garment& garment, GarmentSolver&, const ClothSubstep&) {
        for (const SpringPhase* warp : {&t.warp1, &t.warp2}) {
            for (std::size_t s = 0; s < warp->size(); ++s) {
                const bool pinned_a = garment.state.inv_mass[warp->a[s]] == 0, pinned_b = garment.state.inv_mass[warp->b[s]] == 0;
                if (pinned_a && pinned_b) continue;  // the skin decides
                const Real length = (garment.state.x.col(warp->b[s]) - garment.state.x.col(warp->a[s])).norm();
                ASSERT_LE(length, Real(1.10) * warp->rest_m[s] * Real(1 + 1e-5) + Real(1e-6))
                    << (warp == &t.warp1 ? "layer-1" : "layer-2") << " warp spring " << s
                    << (pinned_a || pinned_b ? " from a pinned particle" : "") << ", frame " << frame;
                if (warp == &t.warp2 && (pinned_a || pinned_b)) ++below_pins;
            }
        }
        if (!simplified) return;
        compute_layer1_normals(t, garment.state.x, normals);
        for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
            if (garment.state.inv_mass[t.weft_particle[k]] == 0) continue;
            ASSERT_NEAR(weft_plane_distance(t, normals, garment.state.x, k), 0, 1e-5) << "layer-2 entry " << k;
            ++on_planes;
        }
    };
    for (; frame < c.frames && !::testing::Test::HasFatalFailure(); ++frame) {
        // The body's systems as the scheduler runs them, then the cloth by hand.
        FrameContext ctx;
        ctx.frame = static_cast<std::uint64_t>(frame);
        ctx.frame_dt_s = ctx.fixed_dt_s = dt;
        ctx.time_s = frame * dt;
        ctx.steps = 1;
        world->scheduler.run_phase(world->registry, Phase::input, ctx);
        world->scheduler.run_phase(world->registry, Phase::animation, ctx);
        world->scheduler.run_phase(world->registry, Phase::skinning, ctx);
        step_garment(world->registry, g, solver, dt, ClothSolverSettings{}, hooks);
    }
    if (simplified) {
        EXPECT_GT(below_pins, 1000u);
        EXPECT_GT(on_planes, 10000u);
    }
}

INSTANTIATE_TEST_SUITE_P(
    Garments, WarpLimitOnTheWalkingAvatar,
    ::testing::Values(WalkCase{GarmentType::skirt, ClothModel::simplified, 600},
                      WalkCase{GarmentType::skirt, ClothModel::classic, 300},
                      WalkCase{GarmentType::dress, ClothModel::simplified, 300},
                      WalkCase{GarmentType::dress, ClothModel::classic, 120}),
    [](const auto& info) {
        return std::string(garment_type_name(info.param.garment)) + "_" + cloth_model_name(info.param.model);
    });

}  // namespace
}  // namespace drape
