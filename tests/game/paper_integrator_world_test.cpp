// The paper's integrator (docs/cloth.md "Two integrators") on the sample scene's walk:
// explicit springs at the cotton material's modulus diverge at one substep per 1/60 s step,
// and hold with the substeps of their own stability bound (integrator.hpp
// spring_step_limit_s), beyond the shipped solver's cap of 8.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "drape/components/animation_player.hpp"
#include "drape/components/garment.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/stats.hpp"
#include "drape/game/world.hpp"
#include "drape/systems/cloth/garment_config.hpp"
#include "drape/systems/cloth/garment_quality.hpp"
#include "tests/figures.hpp"

namespace drape {
namespace {

struct PaperRun {
    GarmentStats stats;
    int substeps = 0;  ///< Of the last step.
};

PaperRun paper_walk(int substeps, int frames) {
    SceneDescription scene = sample_scene();
    scene.garments.at(0).integrator = ClothIntegrator::paper;
    scene.garments.at(0).parameters.push_back({"inertia_max_fall_m_s2", 0.0});  // eq. 2 as written
    scene.solver.substeps = substeps;
    scene.solver.settle_s = 0;  // from the first frame: the settling would diverge the same way
    PaperRun run;
    auto world = build_world(scene, {});
    EXPECT_TRUE(world) << (world ? "" : world.error().message);
    if (!world) return run;
    for (int frame = 0; frame < frames; ++frame) EXPECT_TRUE(step_world(*world, 1.0 / 60.0));
    run.stats = run_stats(*world).garments.at(0);
    run.substeps = world->registry.get<Garment>(world->garments.at(0)).counters.substeps;
    return run;
}

TEST(PaperIntegrator, OneSubstepDivergesOnTheWalk) {
    const PaperRun run = paper_walk(1, 30);
    EXPECT_GT(run.stats.nonfinite + run.stats.resets, 0u) << "strain max " << run.stats.strain_max;
}

// With its own substeps: nothing non-finite, no reset, the warp and weft held by Provot's
// limit (p99 at 10 %, measured 9.9 % with a max of 11.2 % over 300 frames), nothing flung.
// Not the whole contract: stretch springs alone let its weft crumple (shortest spring 5 % of
// its rest length), and nothing repairs a spring a push-out stretched. Labelled `figures`:
// the short form asserts only that it runs clean.
TEST(PaperIntegrator, ItsOwnSubstepsHoldOnTheWalk) {
    const PaperRun run = paper_walk(0, test::frames(120));
    EXPECT_EQ(run.stats.nonfinite, 0u);
    if (test::short_form()) return;
    EXPECT_EQ(run.stats.resets, 0u);
    EXPECT_GT(run.substeps, 8);
    EXPECT_LE(run.stats.strain_p99, 0.105);
    EXPECT_LE(run.stats.strain_max, 0.20);
    EXPECT_LE(run.stats.rise_above_pins_m, 0.05);
    EXPECT_LE(run.stats.penetration_after_frame_m, 2e-3);
}

// A stiff cloth (1e5 N/m) on the walk played at 2.5x, 1/240 s steps, its own substeps (814
// per step): 180 steps without the kinetic energy growing (the stability bench's rule: its
// peak over the last 60 steps at most 10x that before). Provot's passes over the springs
// with layer-2 particles move layer-1 ends to answer layer 2's placement; given to layer 1 as
// velocity, d / h of those moves pumped energy in at this many substeps (0.09 J over the
// first 120 steps, 5.2 J in the last 60: the stability bench's divergence). Labelled
// `figures`: the short form runs 36 steps and asserts only that they run clean.
TEST(PaperIntegrator, AStiffSkirtOnARunKeepsItsEnergy) {
    SceneDescription scene = sample_scene();
    scene.garments.at(0).integrator = ClothIntegrator::paper;
    scene.garments.at(0).parameters.push_back({"inertia_max_fall_m_s2", 0.0});  // eq. 2 as written
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    Registry& r = world->registry;
    const Entity garment = world->garments.at(0);
    ASSERT_TRUE(step_world(*world, 1.0 / 240.0));
    ClothMaterial stiff = r.get<Garment>(garment).config.material;
    stiff.stretch_N_m = Real(1e5);
    ASSERT_TRUE(set_garment_material(r, garment, stiff));
    reset_garments(*world);
    r.get<AnimationPlayer>(world->characters.at(0)).speed = 2.5;
    std::vector<double> energy;
    for (int frame = 0; frame < test::frames(180); ++frame) {
        ASSERT_TRUE(step_world(*world, 1.0 / 240.0));
        const Garment& g = r.get<Garment>(garment);
        energy.push_back(kinetic_energy_J(g.state.v, g.state.inv_mass));
    }
    if (test::short_form()) {
        EXPECT_EQ(run_stats(*world).garments.at(0).nonfinite, 0u);
        return;
    }
    const double before = *std::max_element(energy.begin(), energy.begin() + 120);
    const double after = *std::max_element(energy.begin() + 120, energy.end());
    EXPECT_LE(after, 10 * before) << "peak kinetic energy " << before << " J over the first 120 steps";
    const GarmentStats stats = run_stats(*world).garments.at(0);
    EXPECT_EQ(stats.nonfinite, 0u);
    EXPECT_EQ(stats.resets, 1u);  // the test's own, with the stiff material
    EXPECT_GT(r.get<Garment>(garment).counters.substeps, 8);
}

}  // namespace
}  // namespace drape
