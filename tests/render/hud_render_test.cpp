// The frame budget overlay drawn for real off-screen (Mesa): it changes pixels in the
// frame's top-left corner and none at its centre, it fits in that corner at 640x360 and at
// 1280x720, the same overlay draws the same pixels, and a scene with a second garment
// draws a different overlay from a scene with one.
#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "drape/engine/render/hud_layout.hpp"
#include "drape/engine/render/renderer.hpp"
#include "drape/game/frame_hud.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/world.hpp"

namespace drape {
namespace {

constexpr double nominal_wall_ms = 16.0;  ///< A frame time to record: a figure to show, not a measurement.

/// Plays a scene for some frames at 640x360 and returns its overlay.
HudOverlay played_overlay(const SceneDescription& scene, int frames = 8) {
    WorldOptions options;
    options.render = true;
    options.width = 640;
    options.height = 360;
    auto world = build_world(scene, options);
    EXPECT_TRUE(world) << world.error().message;
    if (!world) return {};
    FrameHud hud;
    for (int frame = 0; frame < frames; ++frame) {
        EXPECT_TRUE(step_world(*world, 1.0 / 60.0));
        hud.record(*world, nominal_wall_ms);
    }
    return hud.overlay();
}

SceneDescription two_garment_scene() {
    SceneDescription scene = sample_scene();
    CharacterDescription second = scene.characters.at(0);
    second.position_m += Vec3(1.2f, 0, 0);
    scene.characters.push_back(second);
    GarmentDescription garment = scene.garments.at(0);
    garment.character = 1;
    scene.garments.push_back(garment);
    return scene;
}

/// The sky and ground only, with an overlay over it or none.
Image frame_with(Renderer& renderer, const HudOverlay* hud) {
    renderer.draw(DrawList{});
    if (hud != nullptr) renderer.draw_hud(*hud);
    auto image = renderer.read_pixels();
    EXPECT_TRUE(image) << image.error().message;
    return image ? *image : Image{};
}

/// Pixels that differ between two images of one size within [x0, x1) x [y0, y1).
int differing(const Image& a, const Image& b, int x0, int y0, int x1, int y1) {
    int count = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const std::uint8_t* p = a.at(x, y);
            const std::uint8_t* q = b.at(x, y);
            count += (p[0] != q[0] || p[1] != q[1] || p[2] != q[2]) ? 1 : 0;
        }
    return count;
}

TEST(HudRender, OverlayChangesItsCornerAndNotTheCentre) {
    WorldOptions options;
    options.render = true;
    options.width = 640;
    options.height = 360;
    auto world = build_world(sample_scene(), options);
    ASSERT_TRUE(world) << world.error().message;
    FrameHud hud;
    for (int frame = 0; frame < 8; ++frame) {
        ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        hud.record(*world, nominal_wall_ms);
    }
    auto plain = world->renderer->read_pixels();
    ASSERT_TRUE(plain) << plain.error().message;
    world->renderer->draw_hud(hud.overlay());
    auto shown = world->renderer->read_pixels();
    ASSERT_TRUE(shown) << shown.error().message;
    if (const char* dump = std::getenv("DRAPE_TEST_DUMP"); dump != nullptr) (void)write_png(*shown, dump);

    const int w = plain->width, h = plain->height;
    const int corner = differing(*plain, *shown, 0, 0, w / 4, h / 4);
    EXPECT_GT(corner, w / 4 * h / 4 / 2) << "the panel darkens its corner";
    EXPECT_EQ(differing(*plain, *shown, w / 2 - 30, h / 2 - 30, w / 2 + 30, h / 2 + 30), 0) << "the centre is untouched";
    EXPECT_EQ(differing(*plain, *shown, w / 2, 0, w, h), 0) << "the right half is untouched";
    EXPECT_EQ(differing(*plain, *shown, 0, h * 3 / 5, w, h), 0) << "the lower part is untouched";
}

TEST(HudRender, PanelFitsItsCornerAtBothSizes) {
    const HudOverlay hud = played_overlay(two_garment_scene(), 2);
    ASSERT_GE(hud.bars.size(), 5u);
    std::vector<render_detail::HudVertex> vertices;
    // 960x540 is a window's size between the two: at scale 2 the panel covered more than
    // half of it, the walking character's chest included.
    struct Size {
        int w, h, scale;
    };
    for (auto [w, h, expected_scale] : {Size{640, 360, 1}, Size{960, 540, 1}, Size{1280, 720, 2}, Size{1920, 1080, 3}, Size{800, 900, 1}}) {
        const auto extent = render_detail::layout_hud(hud, w, h, vertices);
        const int scale = render_detail::hud_scale(w, h);
        EXPECT_EQ(scale, expected_scale) << w << "x" << h;
        EXPECT_LT(extent.width, w / 2) << w << "x" << h;
        EXPECT_LT(extent.height, h * 3 / 5) << w << "x" << h;
        EXPECT_GT(vertices.size(), 1000u);
        for (const auto& v : vertices) {
            EXPECT_LE(v.x, float(extent.width + 6 * scale));
            EXPECT_LE(v.y, float(extent.height + 6 * scale));
        }
    }
}

TEST(HudRender, SecondGarmentDrawsADifferentOverlay) {
    const HudOverlay one = played_overlay(sample_scene());
    const HudOverlay two = played_overlay(two_garment_scene());
    ASSERT_GE(one.lines.size(), 3u);
    ASSERT_GE(two.lines.size(), 3u);
    EXPECT_NE(one.lines[1].find("garments 1 "), std::string::npos) << one.lines[1];
    EXPECT_NE(two.lines[1].find("garments 2 "), std::string::npos) << two.lines[1];
    // The same systems in both; the cloth ran in both.
    ASSERT_EQ(one.bars.size(), two.bars.size());
    for (std::size_t i = 0; i < one.bars.size(); ++i) EXPECT_EQ(one.bars[i].name, two.bars[i].name);
    for (const HudOverlay* hud : {&one, &two}) {
        bool cloth_ran = false;
        for (const HudBar& bar : hud->bars) cloth_ran |= bar.name == "cloth" && bar.last_ms > 0;
        EXPECT_TRUE(cloth_ran);
    }

    RenderSettings settings;
    settings.width = 640;
    settings.height = 360;
    auto renderer = Renderer::create(settings);
    ASSERT_TRUE(renderer) << renderer.error().message;
    const Image with_one = frame_with(**renderer, &one);
    const Image again = frame_with(**renderer, &one);
    const Image with_two = frame_with(**renderer, &two);
    const Image none = frame_with(**renderer, nullptr);
    EXPECT_EQ(differing(with_one, again, 0, 0, 640, 360), 0) << "the same overlay draws the same pixels";
    EXPECT_GT(differing(with_one, with_two, 0, 0, 320, 216), 0);
    EXPECT_EQ(differing(with_one, none, 320, 0, 640, 360), 0);
}

}  // namespace
}  // namespace drape
