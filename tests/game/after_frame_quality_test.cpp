// The garment after every whole frame (collision included) on the default avatar's walk,
// as the stats contract measures it: no free particle inside an ellipsoid, pinned points
// outside, nothing flung above the pins, nothing non-finite, no reset, and the structural
// strain where the model holds it (docs/cloth.md, "Known limits", lists what it does not).
// The ellipsoid depths hold by construction (the last move of a substep is a push-out), so
// the cloth is also judged on what the solver does not force: how deep it lies behind the
// skin mesh a user sees (game/skin_penetration.hpp) and how far its springs are crushed.
#include <gtest/gtest.h>

#include <filesystem>

#include "drape/game/sample_scene.hpp"
#include "drape/game/stats.hpp"
#include "drape/game/world.hpp"
#include "tests/figures.hpp"

namespace drape {
namespace {

GarmentStats walk(GarmentType type, ClothModel model, int frames) {
    SceneDescription scene = sample_scene();
    scene.garments.at(0).type = type;
    scene.garments.at(0).model = model;
    WorldOptions options;
    options.skin_penetration = true;
    options.skin_penetration_every = 5;  // a fifth of the measuring (the dress: 10,080 particles, 600 frames)
    auto world = build_world(scene, options);
    EXPECT_TRUE(world) << (world ? "" : world.error().message);
    if (!world) return {};
    for (int frame = 0; frame < frames; ++frame) EXPECT_TRUE(step_world(*world, 1.0 / 60.0));
    return run_stats(*world).garments.at(0);
}

// What every garment holds after every frame of the walk.
void expect_clean(const GarmentStats& g) {
    EXPECT_LE(g.penetration_after_frame_m, 0.5e-3);
    EXPECT_LE(g.pins_inside_m, 5e-3);
    EXPECT_LE(g.rise_above_pins_m, 0.05);
    EXPECT_EQ(g.nonfinite, 0u);
    EXPECT_EQ(g.resets, 0u);
    // The collision really had work to do: the measures are not vacuous.
    EXPECT_GT(g.penetration_before_response_m, 1e-3);
}

// Clean, and the structural strain within the contract (p99 <= 10 %, max <= 15 %), over 600
// frames of the walk. Labelled `figures`: the short form asserts only that it runs clean.
// Behind the skin, measured over those frames (release build, AMD
// EPYC): the skirts 1.0-4.0 % of their free particles, at most 9.2 and 9.8 mm deep (the
// simplified and the classic model), the dresses 1.1-1.9 %, 13.9 and 14.9 mm; the bounds
// below are a guard against getting worse, a third above those, not the contract's 2 mm,
// which the cloth does not keep on the skin (docs/cloth.md, "Quality after a frame").
// Compressed: no spring shorter than the contract's 25 % of its rest length. The skirts'
// shortest keeps 62-73 % of its length; the dresses' were crushed to 1.3 % and 0.4 % (a
// collision putting two neighbours on one point of the surface, shear and bend springs
// pressing the hem) before contact repair held the material's compression limit (25 %) as
// it holds the strain limit: this fails where the repair's budget binds or anything after
// it crushes a spring.
void expect_contract(GarmentType type, ClothModel model) {
    const GarmentStats g = walk(type, model, test::frames(600));
    EXPECT_EQ(g.nonfinite, 0u);
    if (test::short_form()) return;
    expect_clean(g);
    EXPECT_LE(g.strain_p99, 0.10);
    EXPECT_LE(g.strain_max, 0.15);
    ASSERT_TRUE(g.skin_measured);
    EXPECT_LE(g.skin_penetration_share, 0.055);
    EXPECT_LE(g.skin_penetration_max_m, type == GarmentType::skirt ? 0.013 : 0.02);
    EXPECT_GE(g.compression_min, 0.25);
}

TEST(AfterFrameQuality, SimplifiedSkirtOnTheWalk) { expect_contract(GarmentType::skirt, ClothModel::simplified); }
TEST(AfterFrameQuality, ClassicSkirtOnTheWalk) { expect_contract(GarmentType::skirt, ClothModel::classic); }
TEST(AfterFrameQuality, SimplifiedDressOnTheWalk) { expect_contract(GarmentType::dress, ClothModel::simplified); }
TEST(AfterFrameQuality, ClassicDressOnTheWalk) { expect_contract(GarmentType::dress, ClothModel::classic); }

}  // namespace
}  // namespace drape
