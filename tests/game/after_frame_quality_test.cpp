// The garment after every whole frame (collision included) on the default avatar's walk,
// as the stats contract measures it: no free particle inside an ellipsoid, pinned points
// outside, nothing flung above the pins, nothing non-finite, no reset, and the structural
// strain where the model holds it (docs/cloth.md, "Known limits", lists what it does not).
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
    auto world = build_world(scene, {});
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
void expect_contract(GarmentType type, ClothModel model) {
    const GarmentStats g = walk(type, model, test::frames(600));
    EXPECT_EQ(g.nonfinite, 0u);
    if (test::short_form()) return;
    expect_clean(g);
    EXPECT_LE(g.strain_p99, 0.10);
    EXPECT_LE(g.strain_max, 0.15);
}

TEST(AfterFrameQuality, SimplifiedSkirtOnTheWalk) { expect_contract(GarmentType::skirt, ClothModel::simplified); }
TEST(AfterFrameQuality, ClassicSkirtOnTheWalk) { expect_contract(GarmentType::skirt, ClothModel::classic); }
TEST(AfterFrameQuality, SimplifiedDressOnTheWalk) { expect_contract(GarmentType::dress, ClothModel::simplified); }
TEST(AfterFrameQuality, ClassicDressOnTheWalk) { expect_contract(GarmentType::dress, ClothModel::classic); }

}  // namespace
}  // namespace drape
