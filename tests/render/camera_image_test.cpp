// Parts of the renderer that need no GPU: camera maths, PNG output, settings checks.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <numbers>

#include <stb/stb_image.h>

#include "drape/engine/render/camera.hpp"
#include "drape/engine/render/image.hpp"
#include "drape/engine/render/renderer.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

TEST(Camera, TargetProjectsToTheImageCentre) {
    Camera camera;
    camera.target = Vec3(1, 2, 3);
    camera.yaw_rad = 0.3f;
    camera.pitch_rad = 0.4f;
    const auto p = camera.project(camera.target, 640, 480);
    ASSERT_TRUE(p);
    EXPECT_NEAR(p->x_px, 320, 1e-3);
    EXPECT_NEAR(p->y_px, 240, 1e-3);
    EXPECT_NEAR((camera.eye() - camera.target).norm(), camera.distance_m, 1e-5);
}

TEST(Camera, YawZeroLooksDownMinusZWithXToTheRightAndYUp) {
    Camera camera;
    camera.target = Vec3::Zero();
    camera.yaw_rad = 0;
    camera.pitch_rad = 0;
    EXPECT_TRUE(camera.eye().isApprox(Vec3(0, 0, camera.distance_m)));
    const auto right = camera.project(Vec3(0.1f, 0, 0), 100, 100);
    const auto up = camera.project(Vec3(0, 0.1f, 0), 100, 100);
    ASSERT_TRUE(right && up);
    EXPECT_GT(right->x_px, 50);
    EXPECT_LT(up->y_px, 50);  // image rows grow downward
}

TEST(Camera, PointsBehindTheCameraDoNotProject) {
    Camera camera;
    camera.target = Vec3::Zero();
    camera.yaw_rad = 0;
    camera.pitch_rad = 0;
    EXPECT_FALSE(camera.project(Vec3(0, 0, camera.distance_m + 1), 100, 100));
    EXPECT_FALSE(camera.project(Vec3::Zero(), 0, 100));
}

TEST(Camera, OrbitClampsPitchAndZoomClampsDistance) {
    Camera camera;
    camera.orbit(0, 1e6f);
    EXPECT_LT(camera.pitch_rad, Real(std::numbers::pi / 2));
    camera.orbit(0, -1e6f);
    EXPECT_GT(camera.pitch_rad, -Real(std::numbers::pi / 2));
    camera.zoom(1000);
    EXPECT_FLOAT_EQ(camera.distance_m, 0.3f);
    camera.zoom(-1000);
    EXPECT_FLOAT_EQ(camera.distance_m, 50.0f);
}

TEST(Image, PngRoundTripKeepsEveryByteTopRowFirst) {
    Image image;
    image.width = 5;
    image.height = 3;
    image.rgba.resize(5 * 3 * 4);
    for (std::size_t i = 0; i < image.rgba.size(); ++i) image.rgba[i] = std::uint8_t(i * 7 + 3);
    const auto path = test::binary_dir() / "render-test-output" / "roundtrip.png";
    ASSERT_TRUE(write_png(image, path).has_value());
    int w = 0, h = 0, channels = 0;
    unsigned char* data = stbi_load(path.c_str(), &w, &h, &channels, 4);
    ASSERT_NE(data, nullptr);
    EXPECT_EQ(w, 5);
    EXPECT_EQ(h, 3);
    EXPECT_TRUE(std::equal(image.rgba.begin(), image.rgba.end(), data));
    stbi_image_free(data);
}

TEST(Image, WritingToAnUnwritablePathNamesThePath) {
    Image image{2, 2, std::vector<std::uint8_t>(16, 255)};
    auto ok = write_png(image, "/proc/drape-cannot-write-here/frame.png");
    ASSERT_FALSE(ok.has_value());
    EXPECT_NE(ok.error().message.find("/proc/drape-cannot-write-here"), std::string::npos) << ok.error().message;
}

TEST(Image, AnImageWhoseBytesDoNotMatchItsSizeIsRefused) {
    Image image{4, 4, std::vector<std::uint8_t>(10)};
    auto ok = write_png(image, test::binary_dir() / "render-test-output" / "bad.png");
    ASSERT_FALSE(ok.has_value());
    EXPECT_NE(ok.error().message.find("expected 64"), std::string::npos) << ok.error().message;
    EXPECT_FALSE(write_png(Image{}, "empty.png").has_value());
}

TEST(RenderSettings, ValidationNamesTheField) {
    RenderSettings s;
    s.width = 0;
    auto ok = validate(s);
    ASSERT_FALSE(ok.has_value());
    EXPECT_NE(ok.error().message.find("width"), std::string::npos);
    s = {};
    s.msaa_samples = -2;
    EXPECT_NE(validate(s).error().message.find("msaa_samples"), std::string::npos);
    s = {};
    s.clear_color = Vec3(2, 0, 0);
    EXPECT_NE(validate(s).error().message.find("clear_color"), std::string::npos);
    s = {};
    EXPECT_TRUE(validate(s).has_value());
    s.height = 100000;
    auto created = Renderer::create(s);
    ASSERT_FALSE(created.has_value());
    EXPECT_NE(created.error().message.find("height"), std::string::npos);
}

TEST(RenderSettings, AWindowWithoutADisplayIsAClearError) {
    const char* saved = std::getenv("DISPLAY");
    const std::string previous = saved != nullptr ? saved : "";
    unsetenv("DISPLAY");
    RenderSettings s;
    s.target = RenderTarget::window;
    auto created = Renderer::create(s);
    if (saved != nullptr) setenv("DISPLAY", previous.c_str(), 1);
    ASSERT_FALSE(created.has_value());
    EXPECT_NE(created.error().message.find("DISPLAY"), std::string::npos) << created.error().message;
}

}  // namespace
}  // namespace drape
