// The real sample scene rendered off-screen (Mesa): the image is not uniform, and the
// skirt's colour and the avatar's skin appear where the camera projects them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <set>
#include <string>

#include "drape/components/garment.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/engine/render/renderer.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/world.hpp"
#include "drape/systems/skin_cover_system.hpp"
#include "drape/systems/skinning_system.hpp"

namespace drape {
namespace {

struct Rgb {
    int r, g, b;
};

Rgb pixel(const Image& image, int x, int y) {
    const std::uint8_t* p = image.at(x, y);
    return {p[0], p[1], p[2]};
}

std::string describe(Rgb c) {
    std::string s = "(";
    s += std::to_string(c.r) + ", ";
    s += std::to_string(c.g) + ", ";
    s += std::to_string(c.b) + ")";
    return s;
}

// Share of pixels in a square of half-size `radius` around (x, y) for which `test` holds.
template <class Test>
double share_around(const Image& image, const ScreenPoint& at, int radius, Test test) {
    int hits = 0, total = 0;
    for (int y = static_cast<int>(at.y_px) - radius; y <= static_cast<int>(at.y_px) + radius; ++y)
        for (int x = static_cast<int>(at.x_px) - radius; x <= static_cast<int>(at.x_px) + radius; ++x) {
            if (x < 0 || y < 0 || x >= image.width || y >= image.height) continue;
            ++total;
            hits += test(pixel(image, x, y)) ? 1 : 0;
        }
    return total ? double(hits) / total : 0.0;
}

TEST(SampleSceneRender, SkirtAndAvatarAppearWhereTheCameraPutsThem) {
    WorldOptions options;
    options.render = true;
    options.width = 640;
    options.height = 360;
    auto world = build_world(sample_scene(), options);
    ASSERT_TRUE(world) << world.error().message;
    ASSERT_NE(world->renderer, nullptr);
    for (int frame = 0; frame < 20; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    auto image = world->renderer->read_pixels();
    ASSERT_TRUE(image) << image.error().message;
    ASSERT_EQ(image->width, 640);
    ASSERT_EQ(image->height, 360);
    if (const char* dump = std::getenv("DRAPE_TEST_DUMP"); dump != nullptr) (void)write_png(*image, dump);

    // Not uniform: sky, ground, body and cloth give many colours.
    std::set<std::uint32_t> colours;
    for (int y = 0; y < image->height; y += 4)
        for (int x = 0; x < image->width; x += 4) {
            const Rgb c = pixel(*image, x, y);
            colours.insert(static_cast<std::uint32_t>(c.r << 16 | c.g << 8 | c.b));
        }
    EXPECT_GT(colours.size(), 100u);

    const Camera& camera = world->renderer->camera();
    // The skirt's red (linear 0.75, 0.12, 0.18, lit and in sRGB about (190, 90, 110)) around
    // the projection of its centre.
    const Garment& skirt = world->registry.get<Garment>(world->garments[0]);
    const Vec3 skirt_centre = skirt.state.x.rowwise().mean();
    const auto skirt_px = camera.project(skirt_centre, image->width, image->height);
    ASSERT_TRUE(skirt_px.has_value());
    const double red = share_around(*image, *skirt_px, 6, [](Rgb c) { return c.r > std::max(c.g, c.b) + 50; });
    EXPECT_GT(red, 0.5) << "skirt centre projects to (" << skirt_px->x_px << ", " << skirt_px->y_px << "), colour "
                        << describe(pixel(*image, int(skirt_px->x_px), int(skirt_px->y_px)));

    // The avatar's skin (warm, not the blue-grey sky or the grey ground) at its chest:
    // 0.3 m below the top of the skinned body, at the body's horizontal centre.
    const SkinnedMesh& body = world->registry.get<SkinnedMesh>(world->characters[0]);
    Vec3 chest = body.positions.rowwise().mean();
    chest.y() = body.positions.row(1).maxCoeff() - 0.3f;
    const auto chest_px = camera.project(chest, image->width, image->height);
    ASSERT_TRUE(chest_px.has_value());
    const double skin = share_around(*image, *chest_px, 3, [](Rgb c) { return c.r > c.b + 15 && c.g > c.b; });
    EXPECT_GT(skin, 0.5) << "chest projects to (" << chest_px->x_px << ", " << chest_px->y_px << "), colour "
                         << describe(pixel(*image, int(chest_px->x_px), int(chest_px->y_px)));

    // Far above the avatar there is sky: bluer than red.
    const ScreenPoint top{static_cast<float>(image->width) / 2, 4, 0};
    EXPECT_GT(share_around(*image, top, 3, [](Rgb c) { return c.b > c.r; }), 0.9);
}

}  // namespace
}  // namespace drape

namespace drape {
namespace {

TEST(SampleSceneRender, MeshIsSkinnedOncePerDrawnFrameNotPerStep) {
    WorldOptions options;
    options.render = true;
    options.width = 320;
    options.height = 180;
    auto world = build_world(sample_scene(), options);
    ASSERT_TRUE(world) << world.error().message;
    const SkinnedMesh& skin = world->registry.get<SkinnedMesh>(world->characters[0]);
    const std::uint64_t vertices = skin.mesh->vertex_count();
    const std::uint64_t at_start = skin.skinned_vertices;
    // Frames of two fixed steps each: the body is posed twice, skinned once.
    constexpr int frames = 5;
    for (int frame = 0; frame < frames; ++frame) {
        auto report = step_world(*world, 2.0 / 60.0);
        ASSERT_TRUE(report);
        EXPECT_EQ(report->steps, 2);
    }
    EXPECT_EQ(skin.skinned_vertices - at_start, frames * vertices);
    EXPECT_EQ(world->scheduler.system_names(Phase::render), (std::vector<std::string>{"skinning", "skin_cover", "garment_surface", "render"}));
    // The drawn body is the current pose: the skinning matrices applied now, and the skirt's
    // cover (systems/skin_cover_system.hpp), give the same vertices.
    const Matrix3X drawn = skin.positions;
    skin_characters(world->registry);
    EXPECT_FALSE(drawn == skin.positions);  // the cover pulled the skin under the skirt in
    cover_skin(world->registry);
    EXPECT_TRUE(drawn == skin.positions);
}

}  // namespace
}  // namespace drape
