// Putting a garment on: it is built around the pose the clip starts in and settles there,
// the body held still, for solver.settle_s before the first frame (game/world.cpp). A
// dress put on straight into a stride must not be flung up over the chest in the first
// frames: their strain and rise above the pins stay within the contract asked of
// characters (strain max <= 20 %, rise <= 15 cm). settle_s = 0 turns it off.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>

#include "drape/components/garment.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/scene_file.hpp"
#include "drape/game/world.hpp"
#include "tests/shared_assets.hpp"
#include "tests/test_paths.hpp"
#include "tests/figures.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

SceneDescription dress_from(const fs::path& file, const std::string& clip, double start_s, double settle_s) {
    SceneDescription scene;
    scene.characters.emplace_back();
    scene.characters[0].file = file;
    scene.characters[0].clip = clip;
    scene.characters[0].start_s = start_s;
    scene.garments.emplace_back();
    scene.garments[0].type = GarmentType::dress;
    scene.solver.settle_s = settle_s;
    return scene;
}

// The first `frames` frames' worst strain and rise above the pins.
GarmentStats first_frames(const SceneDescription& scene, int frames = 30) {
    auto world = build_world(scene, {});
    EXPECT_TRUE(world) << (world ? "" : world.error().message);
    if (!world) return {};
    for (int frame = 0; frame < frames; ++frame) EXPECT_TRUE(step_world(*world, 1.0 / 60.0));
    return run_stats(*world).garments.at(0);
}

void expect_put_on(const GarmentStats& g) {
    EXPECT_LE(g.strain_max, 0.20);
    EXPECT_LE(g.rise_above_pins_m, 0.15);
    EXPECT_LE(g.penetration_after_frame_m, 2e-3);
    EXPECT_EQ(g.nonfinite, 0u);
    EXPECT_EQ(g.resets, 0u);
}

TEST(PuttingOn, TheGarmentSettlesBeforeTheFirstFrameAndNotWhenTurnedOff) {
    const fs::path avatar = sample_scene().characters.at(0).file;
    for (const double settle_s : {0.5, 0.0}) {
        auto world = build_world(dress_from(avatar, "Walk", 0.3, settle_s), {});
        ASSERT_TRUE(world) << world.error().message;
        const Garment& g = world->registry.get<Garment>(world->garments.at(0));
        EXPECT_EQ(g.counters.steps, settle_s > 0 ? 30u : 0u);  // 0.5 s of 1/60 s steps
        // Not frames: the stats and the profile start after.
        ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        EXPECT_EQ(run_stats(*world).frames, 1u);
    }
}

TEST(PuttingOn, SettleIsASceneOption) {
    const std::string avatar = fs::absolute(sample_scene().characters.at(0).file).string();
    const std::string head = R"({"characters": [{"file": ")" + avatar + R"("}], "solver": {"settle_s": )";
    auto off = parse_scene(head + "0}}", "scene.json", {});
    ASSERT_TRUE(off) << off.error().message;
    EXPECT_EQ(off->solver.settle_s, 0.0);
    auto absent = parse_scene(R"({"characters": [{"file": ")" + avatar + R"("}]})", "scene.json", {});
    ASSERT_TRUE(absent) << absent.error().message;
    EXPECT_EQ(absent->solver.settle_s, 0.5);
    auto bad = parse_scene(head + "-1}}", "scene.json", {});
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("solver.settle_s: must be a number in [0, 10]"), std::string::npos) << bad.error().message;
}

// The default avatar's dress put on at four points of its walk, a thigh or a shin raised
// into the tube at each. Labelled `figures`: the short form puts it on at the first point
// and asserts only that it runs clean.
TEST(PuttingOn, ADressPutOnMidStrideStartsWithinTheContract) {
    const fs::path avatar = sample_scene().characters.at(0).file;
    constexpr double starts_s[] = {0.15, 0.4, 0.7, 0.95};
    for (const double start_s : test::cases(starts_s)) {
        SCOPED_TRACE("Walk from " + std::to_string(start_s) + " s");
        const GarmentStats g = first_frames(dress_from(avatar, "Walk", start_s, 0.5));
        EXPECT_EQ(g.nonfinite, 0u);
        if (test::short_form()) continue;
        expect_put_on(g);
    }
}

// Shared characters put on in a dress in the first poses of their runs, a knee raised high,
// should start within the contract: not flung (rise above the pins, penetration, nothing
// non-finite, no reset) and not torn. Which of them fails depends on the rounding of the
// build (docs/characters.md). In the tests' build (DRAPE_ARCH x86-64-v3, AMD EPYC), with the
// fall bound on, the trunk's thin shells thickened inward and its thin pieces left out of
// the garment's collision (all defaults), 11 of the 12 hold; the one that fails is torn, not
// flung: Female_Alternative's put on 0.1 s into her run (92.1 %, frame 19, a weft spring of
// the hem over a lower leg). With the thin pieces collided, 9 of the 12 held: her 0.2 s tore
// too (85.8 %, a warp spring straddling a trunk piece 1.0 cm thin), and Female_TankTop's at
// 0.1 s (34.4 %, a weft spring over a lower leg). Rendered, no dress is over the chest or the
// face. Disabled until every run holds (the motion suite, docs/reports/motions.md); run it
// with --gtest_also_run_disabled_tests.
TEST(PuttingOn, DISABLED_ADressPutOnARunningCharacterStartsWithinTheContract) {
    const std::pair<const char*, const char*> runs[] = {{"characters/female_tanktop/Female_TankTop.fbx", "Female_Run"},
                                                        {"characters/female_alternative/Female_Alternative.fbx", "Female_Run"},
                                                        {"characters/robot_expressive/RobotExpressive.glb", "Running"},
                                                        {"characters/male_longsleeve/Male_LongSleeve.fbx", "Man_Run"}};
    for (const auto& [relative, clip] : runs) {
        const fs::path file = test::shared_assets() / relative;
        DRAPE_REQUIRE_SHARED(file);
        for (const double start_s : {0.0, 0.1, 0.2}) {
            SCOPED_TRACE(std::string(relative) + ", " + clip + " from " + std::to_string(start_s) + " s");
            expect_put_on(first_frames(dress_from(file, clip, start_s, 0.5), 20));
        }
    }
}

}  // namespace
}  // namespace drape
