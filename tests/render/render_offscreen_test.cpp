// Off-screen rendering through Mesa (EGL surfaceless, llvmpipe): real frames, inspected
// pixel by pixel where the camera puts known objects.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <set>

#include "drape/components/garment_surface.hpp"
#include "drape/engine/core/scheduler.hpp"
#include "drape/engine/render/renderer.hpp"
#include "drape/engine/render/shaders.hpp"
#include "drape/systems/render_system.hpp"
#include "tests/render/test_scene.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

constexpr int width = 320, height = 240;
const Vec3 body_blue(0.10f, 0.22f, 0.85f);
const Vec3 garment_red(0.85f, 0.08f, 0.08f);

struct Rgb {
    int r, g, b;
};
Rgb pixel(const Image& image, const ScreenPoint& p) {
    const int x = std::clamp(int(p.x_px), 0, image.width - 1), y = std::clamp(int(p.y_px), 0, image.height - 1);
    const auto* q = image.at(x, y);
    return {q[0], q[1], q[2]};
}
int luminance(Rgb c) { return (2 * c.r + 5 * c.g + c.b) / 8; }

void save(const Image& image, const std::string& name) {
    const auto path = test::binary_dir() / "render-test-output" / (name + ".png");
    ASSERT_TRUE(write_png(image, path).has_value());
}

std::unique_ptr<Renderer> make_renderer(int msaa = 4) {
    RenderSettings settings;
    settings.width = width;
    settings.height = height;
    settings.msaa_samples = msaa;
    auto renderer = Renderer::create(settings);
    EXPECT_TRUE(renderer.has_value()) << (renderer ? "" : renderer.error().message);
    if (!renderer) return nullptr;
    Camera& camera = (*renderer)->camera();
    camera.follow = false;
    camera.target = Vec3(0.4f, 0.8f, 0);
    camera.yaw_rad = 0;
    camera.pitch_rad = 0.15f;
    camera.distance_m = 4.0f;
    return std::move(*renderer);
}

/// A blue cylinder "body" at the origin and a red panel "garment" to its right.
struct Scene {
    Registry registry;
    Entity body, garment;
    Scene() {
        body = registry.create();
        registry.emplace<SkinnedMesh>(body, test::make_cylinder_body(0, 0, 0.2f, 1.6f, body_blue));
        registry.emplace<Character>(body);
        garment = registry.create();
        registry.emplace<Garment>(garment, test::make_panel(0.6f, 0.4f, 0.1f, 0.8f, 17, garment_red));
    }
    Vec3 panel_centre() { return registry.get<Garment>(garment).state.x.rowwise().mean(); }
};

Image render(Renderer& renderer, Registry& registry) {
    draw_registry(renderer, registry);
    auto image = renderer.read_pixels();
    EXPECT_TRUE(image.has_value()) << (image ? "" : image.error().message);
    return image ? std::move(*image) : Image{};
}

TEST(RenderOffscreen, ContextIsOpenGL45OnASurfacelessOrDeviceDisplay) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    const RendererInfo& info = renderer->info();
    EXPECT_TRUE(info.platform == "surfaceless" || info.platform == "device") << info.platform;
    EXPECT_NE(info.gl_version.find("4."), std::string::npos) << info.gl_version;
    EXPECT_EQ(info.msaa_samples, 4) << info.gl_renderer;
}

TEST(RenderOffscreen, AutomaticMultisamplingIsOffOnASoftwareRasteriser) {
    RenderSettings settings;
    settings.width = 64;
    settings.height = 64;
    ASSERT_EQ(settings.msaa_samples, -1);
    auto renderer = Renderer::create(settings);
    ASSERT_TRUE(renderer.has_value()) << renderer.error().message;
    const RendererInfo& info = (*renderer)->info();
    const bool software = info.gl_renderer.find("llvmpipe") != std::string::npos ||
                          info.gl_renderer.find("softpipe") != std::string::npos;
    EXPECT_EQ(info.msaa_samples, software ? 0 : 4) << info.gl_renderer;
}

TEST(RenderOffscreen, ShaderErrorsNameTheProgramTheStageAndTheLog) {
    auto renderer = make_renderer();  // a current context
    ASSERT_TRUE(renderer);
    auto broken = render_detail::build_program("broken", render_detail::lit_vertex_shader,
                                               "#version 450 core\nout vec4 o;\nvoid main() { o = no_such_thing; }\n");
    ASSERT_FALSE(broken.has_value());
    const std::string& message = broken.error().message;
    EXPECT_NE(message.find("shader broken (fragment): compile error"), std::string::npos) << message;
    EXPECT_NE(message.find("no_such_thing"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
    // Stages that compile but do not link (the fragment stage reads what no vertex stage writes).
    auto unlinked = render_detail::build_program(
        "unlinked", "#version 450 core\nvoid main() { gl_Position = vec4(0.0); }\n",
        "#version 450 core\nin vec3 v_missing;\nout vec4 o;\nvoid main() { o = vec4(v_missing, 1.0); }\n");
    ASSERT_FALSE(unlinked.has_value());
    EXPECT_NE(unlinked.error().message.find("shader unlinked: link error"), std::string::npos)
        << unlinked.error().message;
}

TEST(RenderOffscreen, ReadPixelsBeforeAnyFrameIsAnError) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    auto image = renderer->read_pixels();
    ASSERT_FALSE(image.has_value());
    EXPECT_NE(image.error().message.find("before any frame"), std::string::npos) << image.error().message;
}

TEST(RenderOffscreen, FrameIsNotUniformAndShowsBodyGarmentGroundAndSky) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Scene scene;
    const Image image = render(*renderer, scene.registry);
    ASSERT_EQ(image.width, width);
    ASSERT_EQ(image.height, height);
    save(image, "scene");

    std::set<std::uint32_t> colours;
    for (std::size_t i = 0; i < image.rgba.size(); i += 4)
        colours.insert(std::uint32_t(image.rgba[i]) << 16 | std::uint32_t(image.rgba[i + 1]) << 8 | image.rgba[i + 2]);
    EXPECT_GT(colours.size(), 200u) << "the frame is (nearly) uniform";

    const Camera& camera = renderer->camera();
    // The garment's colour where its centre particle projects.
    const auto garment_px = camera.project(scene.panel_centre(), width, height);
    ASSERT_TRUE(garment_px);
    const Rgb garment = pixel(image, *garment_px);
    EXPECT_GT(garment.r, garment.g + 60) << "garment pixel " << garment.r << "," << garment.g << "," << garment.b;
    EXPECT_GT(garment.r, garment.b + 60);

    // The body's colour at the middle of its front.
    const auto body_px = camera.project(Vec3(0, 0.8f, 0.2f), width, height);
    ASSERT_TRUE(body_px);
    const Rgb body = pixel(image, *body_px);
    EXPECT_GT(body.b, body.r + 60) << "body pixel " << body.r << "," << body.g << "," << body.b;
    EXPECT_GT(body.b, body.g + 30);

    // Ground in front of the objects: grey, not the sky.
    const auto ground_px = camera.project(Vec3(-1.2f, 0, 1.2f), width, height);
    ASSERT_TRUE(ground_px);
    const Rgb ground = pixel(image, *ground_px);
    EXPECT_LT(std::abs(ground.r - ground.g), 25) << "ground pixel " << ground.r << "," << ground.g << "," << ground.b;
    EXPECT_LT(std::abs(ground.g - ground.b), 25);
    const Rgb sky = pixel(image, {width / 2.0f, 2.0f, 0});
    EXPECT_GT(sky.b, ground.b + 20) << "the top row should be sky-blue";
    EXPECT_GT(sky.b, sky.r + 20);
}

TEST(RenderOffscreen, GarmentIsDoubleSidedAndLitFromBehind) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Scene scene;
    Camera& camera = renderer->camera();
    camera.yaw_rad = Real(std::numbers::pi);  // behind the panel: its back faces
    camera.target = scene.panel_centre();
    const Image image = render(*renderer, scene.registry);
    save(image, "garment-back");
    const auto p = camera.project(scene.panel_centre(), width, height);
    ASSERT_TRUE(p);
    const Rgb back = pixel(image, *p);
    EXPECT_GT(back.r, back.g + 40) << back.r << "," << back.g << "," << back.b;
    EXPECT_GT(back.r, 60) << "the back face is shaded with the flipped normal, not black";
}

// A garment drawn as authored with its base-colour texture: a print in four quadrants (green,
// blue above; yellow, white below) over the red panel, mapped by its UVs (u to the right, v
// up), shows each colour where its quadrant lies, and not the garment's own red.
TEST(RenderOffscreen, AGarmentsTextureIsDrawnWhereItsUvsPutIt) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Scene scene;
    const Garment& garment = scene.registry.get<Garment>(scene.garment);
    const Matrix3X& x = garment.state.x;
    const Vec3 low = x.rowwise().minCoeff(), high = x.rowwise().maxCoeff();
    GarmentSurface surface;
    surface.triangles = garment.fabric->triangles;
    surface.carriers.assign(static_cast<std::size_t>(x.cols()), {0, 0, 0});
    surface.positions = x;
    surface.normals = Matrix3X::Zero(3, x.cols());
    surface.normals.row(2).setOnes();
    surface.uvs.resize(2, x.cols());
    for (Eigen::Index i = 0; i < x.cols(); ++i)
        surface.uvs.col(i) = Eigen::Vector2f((x(0, i) - low.x()) / (high.x() - low.x()), (x(1, i) - low.y()) / (high.y() - low.y()));
    auto print = std::make_shared<Image>();
    print->width = print->height = 8;
    for (int py = 0; py < 8; ++py)
        for (int px = 0; px < 8; ++px) {
            const std::uint8_t c[4][3] = {{30, 200, 40}, {30, 40, 220}, {230, 210, 20}, {250, 250, 250}};
            const auto& q = c[(py >= 4 ? 2 : 0) + (px >= 4 ? 1 : 0)];
            print->rgba.insert(print->rgba.end(), {q[0], q[1], q[2], 255});
        }
    surface.base_color = print;
    scene.registry.emplace<GarmentSurface>(scene.garment, surface);
    renderer->camera().target = scene.panel_centre();
    const Image image = render(*renderer, scene.registry);
    save(image, "garment-textured");
    const auto at = [&](Real u, Real v) {
        const Vec3 p(low.x() + u * (high.x() - low.x()), low.y() + v * (high.y() - low.y()), low.z());
        const auto screen = renderer->camera().project(p, width, height);
        EXPECT_TRUE(screen);
        return screen ? pixel(image, *screen) : Rgb{0, 0, 0};
    };
    const Rgb green = at(0.25f, 0.75f), blue = at(0.75f, 0.75f), yellow = at(0.25f, 0.25f), white = at(0.75f, 0.25f);
    EXPECT_GT(green.g, green.r + 40) << green.r << "," << green.g << "," << green.b;
    EXPECT_GT(green.g, green.b + 40) << green.r << "," << green.g << "," << green.b;
    EXPECT_GT(blue.b, blue.r + 40) << blue.r << "," << blue.g << "," << blue.b;
    EXPECT_GT(blue.b, blue.g + 40) << blue.r << "," << blue.g << "," << blue.b;
    EXPECT_GT(std::min(yellow.r, yellow.g), yellow.b + 40) << yellow.r << "," << yellow.g << "," << yellow.b;
    EXPECT_LT(std::max({white.r, white.g, white.b}) - std::min({white.r, white.g, white.b}), 40) << white.r << "," << white.g << "," << white.b;
    EXPECT_GT(luminance(white), luminance(blue) + 40);
    // Without the texture: the garment's red again.
    scene.registry.get<GarmentSurface>(scene.garment).base_color.reset();
    const Image plain = render(*renderer, scene.registry);
    const auto p = renderer->camera().project(Vec3(low.x() + 0.25f * (high.x() - low.x()), low.y() + 0.75f * (high.y() - low.y()), low.z()), width, height);
    ASSERT_TRUE(p);
    const Rgb red = pixel(plain, *p);
    EXPECT_GT(red.r, red.g + 40) << red.r << "," << red.g << "," << red.b;
}

TEST(RenderOffscreen, GarmentNormalsFollowItsParticles) {
    // Tilt the panel each way about a vertical axis: a face turned toward the key light
    // (from the left) is brighter than one turned away, so normals are recomputed.
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Scene scene;
    Garment& garment = scene.registry.get<Garment>(scene.garment);
    const Vec3 centre = scene.panel_centre();
    const Matrix3X flat = garment.state.x;
    auto shade_turned = [&](Real angle_rad) {
        const Mat3 turn = Eigen::AngleAxis<Real>(angle_rad, Vec3::UnitY()).toRotationMatrix();
        garment.state.x = (turn * (flat.colwise() - centre)).colwise() + centre;
        const Image image = render(*renderer, scene.registry);
        return luminance(pixel(image, *renderer->camera().project(centre, width, height)));
    };
    const int toward_light = shade_turned(-0.7f);  // normal swings toward -X, where the key light is
    const int away_from_light = shade_turned(0.7f);
    EXPECT_GT(toward_light, away_from_light + 10);
}

TEST(RenderOffscreen, BodiesCastAContactShadowOnTheGround) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Registry empty_ground;
    Entity marker = empty_ground.create();  // keeps nothing but the ground in view
    (void)marker;
    const Image bare = render(*renderer, empty_ground);
    save(bare, "no-shadow");
    Scene scene;
    const Image shaded = render(*renderer, scene.registry);
    save(shaded, "shadow");
    // Right at the foot of the body, on the side facing the camera.
    const auto p = renderer->camera().project(Vec3(0, 0, 0.25f), width, height);
    ASSERT_TRUE(p);
    EXPECT_LT(luminance(pixel(shaded, *p)) + 15, luminance(pixel(bare, *p)))
        << "at " << p->x_px << "," << p->y_px;
}

TEST(RenderOffscreen, EllipsoidsAreTranslucentAndOnlyWhenShown) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Scene scene;
    const Entity e = scene.registry.create();
    auto& collider = scene.registry.emplace<EllipsoidCollider>(e);
    collider.world = Affine3::Identity();
    collider.world.translate(Vec3(-0.8f, 0.6f, 0));
    collider.world.scale(Vec3(0.25f, 0.4f, 0.25f));
    const auto p = renderer->camera().project(Vec3(-0.8f, 0.6f, 0), width, height);
    ASSERT_TRUE(p);
    const Rgb hidden = pixel(render(*renderer, scene.registry), *p);
    renderer->set_show_ellipsoids(true);
    const Image image = render(*renderer, scene.registry);
    save(image, "ellipsoids");
    const Rgb shown = pixel(image, *p);
    EXPECT_GT(shown.g + shown.b - 2 * shown.r, hidden.g + hidden.b - 2 * hidden.r + 20)
        << "cyan tint expected: hidden " << hidden.r << "," << hidden.g << "," << hidden.b << " shown " << shown.r
        << "," << shown.g << "," << shown.b;
    EXPECT_GT(shown.r, 20) << "translucent: the background still shows through";
}

TEST(RenderOffscreen, SameSceneGivesTheSameBytes) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Scene scene;
    const Image a = render(*renderer, scene.registry);
    const Image b = render(*renderer, scene.registry);
    EXPECT_EQ(a.rgba, b.rgba);
}

TEST(RenderOffscreen, WorksWithoutMultisampling) {
    auto renderer = make_renderer(0);
    ASSERT_TRUE(renderer);
    EXPECT_EQ(renderer->info().msaa_samples, 0);
    Scene scene;
    const Image image = render(*renderer, scene.registry);
    const Rgb garment = pixel(image, *renderer->camera().project(scene.panel_centre(), width, height));
    EXPECT_GT(garment.r, garment.g + 60);
}

TEST(RenderOffscreen, BadGarmentIndicesAreReportedNotDrawn) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Scene scene;
    auto topology = std::make_shared<Fabric>(*scene.registry.get<Garment>(scene.garment).fabric);
    topology->triangles[7] = 100000;
    scene.registry.get<Garment>(scene.garment).fabric = topology;
    draw_registry(*renderer, scene.registry);
    auto image = renderer->read_pixels();
    ASSERT_FALSE(image.has_value());
    EXPECT_NE(image.error().message.find("triangles[7] = 100000"), std::string::npos) << image.error().message;
    // Once fixed, the next frame is fine again.
    topology->triangles[7] = 0;
    draw_registry(*renderer, scene.registry);
    EXPECT_TRUE(renderer->read_pixels().has_value());
}

TEST(RenderOffscreen, SkinnedPositionsNotMatchingTheMeshAreReported) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Scene scene;
    auto& skin = scene.registry.get<SkinnedMesh>(scene.body);
    skin.positions.conservativeResize(3, skin.positions.cols() - 1);
    draw_registry(*renderer, scene.registry);
    auto image = renderer->read_pixels();
    ASSERT_FALSE(image.has_value());
    EXPECT_NE(image.error().message.find("skinned positions"), std::string::npos) << image.error().message;
}

TEST(RenderOffscreen, NonFiniteParticlesNeitherCrashNorMoveTheCamera) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    renderer->camera().follow = true;
    Scene scene;
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    scene.registry.get<Garment>(scene.garment).state.x.col(5).setConstant(nan);
    scene.registry.get<SkinnedMesh>(scene.body).positions.col(3).setConstant(nan);
    update_follow_camera(renderer->camera(), scene.registry, 0);
    EXPECT_TRUE(renderer->camera().target.allFinite()) << "one NaN vertex must not drag the camera away";
    EXPECT_NEAR(renderer->camera().target.y(), 0.55f * 1.6f, 1e-4);
    const Image image = render(*renderer, scene.registry);
    ASSERT_FALSE(image.empty());
    // The rest of the garment still draws in its colour.
    const Rgb garment = pixel(image, *renderer->camera().project(Vec3(1.2f, 0.6f, 0.1f), width, height));
    EXPECT_GT(garment.r, garment.g + 60);
}

TEST(RenderSystem, FollowsTheFirstCharacterAndRendersThroughTheScheduler) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    renderer->camera().follow = true;
    Scene scene;
    // Another skinned mesh that is not a character: the camera must ignore it.
    const Entity prop = scene.registry.create();
    scene.registry.emplace<SkinnedMesh>(prop, test::make_cylinder_body(5, 5, 0.3f, 0.5f, Vec3(0.5f, 0.5f, 0.5f)));
    Scheduler scheduler;
    scheduler.add(make_render_system(*renderer));
    ASSERT_TRUE(scheduler.tick(scene.registry, 1.0 / 60.0).has_value());
    const Vec3 target = renderer->camera().target;
    EXPECT_NEAR(target.x(), 0, 1e-4);
    EXPECT_NEAR(target.z(), 0, 1e-4);
    EXPECT_NEAR(target.y(), 0.55f * 1.6f, 1e-4);
    auto image = renderer->read_pixels();
    ASSERT_TRUE(image.has_value()) << image.error().message;
    // The character sits in the middle of the frame.
    const Rgb centre = pixel(*image, {width / 2.0f, height / 2.0f, 0});
    EXPECT_GT(centre.b, centre.r + 60);
}

TEST(RenderSystem, IsSkippedWithoutSkinnedMeshes) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Registry registry;
    registry.emplace<Garment>(registry.create(), test::make_panel(0, 0, 0, 1, 5, garment_red));
    Scheduler scheduler;
    scheduler.add(make_render_system(*renderer));
    ASSERT_TRUE(scheduler.tick(registry, 1.0 / 60.0).has_value());
    const SystemStats stats = scheduler.profiler().stats("render");
    EXPECT_EQ(stats.runs, 0u);
    EXPECT_EQ(stats.skips, 1u);
}

TEST(RenderSystem, TimeRenderFramesReturnsOneTimePerFrame) {
    auto renderer = make_renderer();
    ASSERT_TRUE(renderer);
    Scene scene;
    auto times = time_render_frames(*renderer, scene.registry, 3);
    ASSERT_TRUE(times.has_value()) << times.error().message;
    ASSERT_EQ(times->size(), 3u);
    for (double ms : *times) EXPECT_GT(ms, 0.0);
    EXPECT_FALSE(time_render_frames(*renderer, scene.registry, 0).has_value());
}

}  // namespace
}  // namespace drape
