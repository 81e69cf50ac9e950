// The overlay's figures (game/frame_hud.hpp) from a played scene: one second of frames
// kept, fps from the recorded frame times, every profiler slot a row, the garments' counts
// and the live strain as GarmentWatch measured it. Frame times here are given figures.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "drape/game/frame_hud.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/world.hpp"

namespace drape {
namespace {

TEST(FrameHud, KeepsOneSecondOfFramesAndShowsTheWorldsFigures) {
    auto world = build_world(sample_scene(), {});
    ASSERT_TRUE(world) << world.error().message;
    FrameHud hud;
    for (int frame = 0; frame < 80; ++frame) {
        ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        hud.record(*world, 20.0);
    }
    EXPECT_EQ(hud.frames(), 50u) << "one second of 20 ms frames";
    EXPECT_DOUBLE_EQ(hud.fps(), 50.0);
    EXPECT_EQ(hud.title(), "Drape  50 fps  20.0 ms");

    const HudOverlay overlay = hud.overlay();
    ASSERT_EQ(overlay.lines.size(), 3u);
    EXPECT_EQ(overlay.lines[0].rfind("50 fps   frame 20.0 ms  p50 20.0  p95 20.0", 0), 0u) << overlay.lines[0];
    EXPECT_EQ(overlay.lines[1].rfind("garments 1  particles 837  substeps ", 0), 0u) << overlay.lines[1];
    const double strain = world->watch.latest_strain_p99();
    EXPECT_GT(strain, 0.0);
    char expected[64];
    std::snprintf(expected, sizeof expected, "strain p99 %.1f %%  budget hits ", 100 * strain);
    EXPECT_EQ(overlay.lines[2].rfind(expected, 0), 0u) << overlay.lines[2];

    const FrameProfiler& profiler = world->scheduler.profiler();
    ASSERT_EQ(overlay.bars.size(), profiler.slot_count());
    for (std::uint32_t i = 0; i < profiler.slot_count(); ++i) {
        const HudBar& bar = overlay.bars[i];
        EXPECT_EQ(bar.name, profiler.slot_name(i));
        EXPECT_EQ(bar.section, profiler.slot_parent(i) != FrameProfiler::no_parent);
        EXPECT_DOUBLE_EQ(bar.last_ms, profiler.last_frame_ms(i));
        EXPECT_LE(bar.p50_ms, bar.p95_ms);
        EXPECT_LE(bar.p95_ms, overlay.full_bar_ms) << bar.name;
    }
}

TEST(FrameHud, FramesWithoutAWallTimeCountTowardsNoSecond) {
    auto world = build_world(sample_scene(), {});
    ASSERT_TRUE(world) << world.error().message;
    FrameHud hud;
    ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    hud.record(*world, 0.0);
    EXPECT_EQ(hud.fps(), 0.0);
    EXPECT_EQ(hud.overlay().lines.at(0).rfind("0 fps", 0), 0u);
}

}  // namespace
}  // namespace drape
