// Worlds built from scene descriptions: the sample scene plays headless and stays finite;
// teleports reset the garment around the body; hitches are clamped; the time scale holds;
// bad scenes fail with one error naming the field.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/components/transform.hpp"
#include "drape/game/asset_paths.hpp"
#include "drape/game/contract.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/scene_file.hpp"
#include "drape/game/world.hpp"
#include "drape/game/scene_garment_parameters.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/substeps.hpp"
#include "tests/shared_assets.hpp"
#include "tests/test_paths.hpp"
#include "tests/figures.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

SceneDescription sample() {
    SceneDescription s = sample_scene();
    if (!fs::exists(s.characters[0].file)) ADD_FAILURE() << "the default avatar is missing: " << s.characters[0].file;
    return s;
}

void clear_locations(SceneDescription& s) {
    for (auto& c : s.characters) c.where = {};
    for (auto& g : s.garments) g.where = {};
    for (auto& c : s.colliders) c.where = {};
}

Vec3 mean_position(const Garment& g) { return g.state.x.rowwise().mean(); }

// The cloth resets a garment that went non-finite, so finite values now prove nothing on
// their own: no garment may have found a non-finite value, and each garment's resets are
// those the world asked for (teleports, explicit resets; one garment per scene here).
void expect_never_nonfinite(const World& world) {
    EXPECT_FALSE(has_nonfinite(world));
    for (Entity e : world.garments) {
        const Garment* g = world.registry.try_get<Garment>(e);
        ASSERT_NE(g, nullptr);
        EXPECT_EQ(g->counters.non_finite_values, 0u);
        EXPECT_EQ(g->counters.resets, world.teleports->resets);
    }
}

TEST(SampleScene, FileAndCodeDescribeTheSameScene) {
    auto file = load_scene_file(asset_dir() / "scenes" / "sample.json");
    ASSERT_TRUE(file) << file.error().message;
    SceneDescription from_file = *file;
    clear_locations(from_file);
    SceneDescription from_code = sample();
    from_code.characters[0].file = from_code.characters[0].file.lexically_normal();
    EXPECT_EQ(from_file, from_code);
}

TEST(SampleScene, EverySceneInAssetsLoads) {
    int scenes = 0;
    for (const auto& entry : fs::directory_iterator(asset_dir() / "scenes")) {
        if (entry.path().extension() != ".json") continue;
        ++scenes;
        auto scene = load_scene_file(entry.path());
        EXPECT_TRUE(scene) << scene.error().message;
    }
    EXPECT_GE(scenes, 2);
}

// The lowest point of each character's skin after the first frame.
std::vector<Real> lowest_points(World& world) {
    std::vector<Real> low;
    for (const Entity e : world.characters) low.push_back(world.registry.get<SkinnedMesh>(e).positions.row(1).minCoeff());
    return low;
}

// RiggedSimple (a bending cylinder) is modelled round its origin: with a floor it stands on
// it (before: its lower half under the floor, the skirt piled on the floor at its middle),
// with one line saying so. The default avatar, modelled standing on its origin, is left
// where it is put, and without a floor nothing moves.
TEST(BuildWorld, ACharacterModelledRoundItsOriginStandsOnTheFloor) {
    const fs::path file = test::shared_assets() / "characters/rigged_simple/RiggedSimple.glb";
    DRAPE_REQUIRE_SHARED(file);
    SceneDescription scene = sample();
    scene.characters.push_back(scene.characters[0]);
    scene.characters[1].file = file;
    scene.characters[1].position_m = Vec3(1, 0, 0);
    scene.characters[1].clip.clear();
    for (const bool ground : {true, false}) {
        SCOPED_TRACE(ground ? "with a floor" : "without a floor");
        scene.ground = ground;
        auto world = build_world(scene, {});
        ASSERT_TRUE(world) << world.error().message;
        ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        const std::vector<Real> low = lowest_points(*world);
        EXPECT_NEAR(low[0], 0, 0.03);  // the avatar's soles
        const auto placed = std::count_if(world->warnings.begin(), world->warnings.end(), [&](const std::string& w) {
            return w.find(file.string() + ": placed on the floor") != std::string::npos;
        });
        if (ground) {
            EXPECT_NEAR(low[1], 0, 0.05);  // the bind pose's lowest point on the floor; the clip bends it a little
            EXPECT_EQ(placed, 1);
        } else {
            EXPECT_LT(low[1], -0.5);
            EXPECT_EQ(placed, 0);
        }
    }
}

TEST(SampleScene, PlaysHeadlessWithFiniteValues) {
    auto world = build_world(sample(), {});
    ASSERT_TRUE(world) << world.error().message;
    ASSERT_EQ(world->characters.size(), 1u);
    ASSERT_EQ(world->garments.size(), 1u);
    EXPECT_EQ(world->renderer, nullptr);
    for (int frame = 0; frame < 90; ++frame) {
        auto report = step_world(*world, 1.0 / 60.0);
        ASSERT_TRUE(report) << report.error().message;
        ASSERT_FALSE(has_nonfinite(*world)) << "frame " << frame;
    }
    const RunStats stats = run_stats(*world);
    EXPECT_EQ(stats.frames, 90u);
    EXPECT_DOUBLE_EQ(stats.sim_dt_s, 1.0 / 60.0);
    ASSERT_EQ(stats.garments.size(), 1u);
    EXPECT_EQ(stats.garments[0].particles, 837u);  // the paper's skirt
    EXPECT_EQ(stats.garments[0].nonfinite, 0u);
    EXPECT_EQ(stats.garments[0].resets, 0u);
    expect_never_nonfinite(*world);
    EXPECT_GT(stats.garments[0].collision_tests_per_frame, 0);
    // No render system in a headless world; the cloth ran every step.
    bool has_render = false, has_cloth = false;
    for (const SystemStats& s : stats.systems) {
        has_render |= s.name == "render";
        if (s.name == "cloth_integration") has_cloth = s.runs >= 90;
    }
    EXPECT_FALSE(has_render);
    EXPECT_TRUE(has_cloth);
    // The skirt stays on the body: its centre near the character's vertical axis.
    const Garment& g = world->registry.get<Garment>(world->garments[0]);
    const Vec3 centre = mean_position(g);
    EXPECT_LT(Vec3(centre.x(), 0, centre.z()).norm(), 0.3f);
    EXPECT_GT(centre.y(), 0.4f);
    // And the contract `drape play` judges it by, with the default walk's 15 % (docs/cloth.md).
    // Labelled `figures`: the short form stops before it.
    if (test::short_form()) return;
    EXPECT_TRUE(contract_breaches(stats.garments[0]).empty()) << garment_verdict("skirt", stats.garments[0]);
    EXPECT_LE(stats.garments[0].strain_max, 0.15);
}

TEST(TeleportGuard, JumpResetsTheGarmentAroundTheBodyAtItsNewPlace) {
    auto world = build_world(sample(), {});
    ASSERT_TRUE(world) << world.error().message;
    for (int frame = 0; frame < 30; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    EXPECT_EQ(world->teleports->teleports, 0u);

    world->registry.get<Transform>(world->characters[0]).position += Vec3(5, 0, 0);
    ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    EXPECT_EQ(world->teleports->teleports, 1u);
    EXPECT_EQ(world->teleports->resets, 1u);
    const Garment& g = world->registry.get<Garment>(world->garments[0]);
    EXPECT_TRUE(g.state.x.allFinite() && g.state.v.allFinite());
    EXPECT_NEAR(mean_position(g).x(), 5.0f, 0.3f);
    // The jump carried no velocity into the cloth.
    EXPECT_LT(g.state.v.colwise().norm().maxCoeff(), 5.0f);
    // Nor into the next step's colliders: they move with the clip again, and no acceleration
    // is taken from the velocity the guard forgot (it would be the clip's velocity over one
    // step, hundreds of m/s^2 at a foot).
    ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    double fastest = 0;
    world->registry.view<EllipsoidCollider>().each([&](Entity, const EllipsoidCollider& c) {
        fastest = std::max(fastest, static_cast<double>(c.velocity_m_s.norm()));
        EXPECT_EQ(c.acceleration_m_s2, Vec3::Zero());
    });
    EXPECT_GT(fastest, 0.1);
    for (int frame = 0; frame < 30; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    expect_never_nonfinite(*world);
    EXPECT_NEAR(mean_position(world->registry.get<Garment>(world->garments[0])).x(), 5.0f, 0.3f);
    EXPECT_EQ(world->teleports->teleports, 1u);
}

TEST(TeleportGuard, AGameMovingItsCharacterIsNoTeleport) {
    auto world = build_world(sample(), {});
    ASSERT_TRUE(world) << world.error().message;
    // Running at 6 m/s, moved by the game every frame, turning as it goes.
    for (int frame = 0; frame < 150; ++frame) {
        Transform& t = world->registry.get<Transform>(world->characters[0]);
        t.rotation = Quat(Eigen::AngleAxis<Real>(Real(0.01) * frame, Vec3::UnitY()));
        t.position += t.rotation * Vec3(0, 0, Real(6.0 / 60.0));
        ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    }
    EXPECT_EQ(world->teleports->teleports, 0u);
    expect_never_nonfinite(*world);
    // The skirt came along.
    const Vec3 body = world->registry.get<Transform>(world->characters[0]).position;
    const Vec3 skirt = mean_position(world->registry.get<Garment>(world->garments[0]));
    EXPECT_LT(Vec3(skirt.x() - body.x(), 0, skirt.z() - body.z()).norm(), 0.4f);
}

TEST(TeleportGuard, ThresholdIsASolverSetting) {
    SceneDescription scene = sample();
    scene.solver.teleport_threshold_m = 10;
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    world->registry.get<Transform>(world->characters[0]).position += Vec3(5, 0, 0);
    ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    EXPECT_EQ(world->teleports->teleports, 0u);
}

// The motion term of the automatic substeps comes from the scene: a shorter surface travel
// per substep takes more substeps on the same walk, up to the scene's cap; the defaults are
// the cloth's own.
TEST(AutomaticSubsteps, MotionTermAndCapAreSolverSettings) {
    EXPECT_FLOAT_EQ(static_cast<Real>(SolverDescription{}.max_surface_travel_m), ClothSolverSettings{}.max_surface_travel_m);
    EXPECT_EQ(SolverDescription{}.max_substeps, ClothSolverSettings{}.max_substeps);
    const auto most_substeps = [](double travel_m, int cap) {
        SceneDescription scene = sample();
        scene.solver.max_surface_travel_m = travel_m;
        scene.solver.max_substeps = cap;
        auto world = build_world(scene, {});
        EXPECT_TRUE(world) << world.error().message;
        if (!world) return 0;
        int most = 0;
        for (int frame = 0; frame < 60; ++frame) {
            EXPECT_TRUE(step_world(*world, 1.0 / 60.0));
            const Garment& g = world->registry.get<Garment>(world->garments.at(0));
            EXPECT_LE(g.counters.substeps, cap);
            most = std::max(most, g.counters.substeps_motion);
        }
        return most;
    };
    const int coarse = most_substeps(0.04, 8);
    const int fine = most_substeps(0.005, 64);
    EXPECT_GT(fine, 2 * coarse) << "an eighth of the travel per substep";
    EXPECT_EQ(most_substeps(0.005, 3), 3) << "the cap holds";
}

TEST(ExplicitReset, PutsTheGarmentBackAroundTheBody) {
    auto world = build_world(sample(), {});
    ASSERT_TRUE(world) << world.error().message;
    for (int frame = 0; frame < 20; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    Garment& g = world->registry.get<Garment>(world->garments[0]);
    g.state.x.colwise() += Vec3(0, 3, 0);  // fling it away
    reset_garments(*world);
    EXPECT_LT(std::abs(mean_position(world->registry.get<Garment>(world->garments[0])).y() - 0.8f), 0.5f);
    EXPECT_EQ(world->teleports->resets, 1u);
}

TEST(Hitches, LongFramesAreClampedThenCapped) {
    SceneDescription scene = sample();
    scene.solver.max_frame_dt_s = 0.1;
    scene.solver.max_steps_per_frame = 8;
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    // A 2 s hitch is clamped to 0.1 s: 6 steps of 1/60 s, nothing left to drop.
    auto report = step_world(*world, 2.0);
    ASSERT_TRUE(report);
    EXPECT_EQ(report->steps, 6);
    EXPECT_NEAR(world->scheduler.time_s(), 0.1, 1e-9);
    expect_never_nonfinite(*world);
    // A bad frame time is an error and nothing runs.
    EXPECT_FALSE(step_world(*world, std::numeric_limits<double>::quiet_NaN()));
    EXPECT_FALSE(step_world(*world, -1.0));
    EXPECT_NEAR(world->scheduler.time_s(), 0.1, 1e-9);
}

TEST(TimeScale, HalfSpeedTakesHalfTheSteps) {
    SceneDescription scene = sample();
    scene.solver.time_scale = 0.5;
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    for (int frame = 0; frame < 60; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    EXPECT_NEAR(world->scheduler.time_s(), 0.5, 1e-9);
    ASSERT_TRUE(set_time_scale(*world, 2.0));
    for (int frame = 0; frame < 30; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    EXPECT_NEAR(world->scheduler.time_s(), 1.5, 1e-9);
    auto bad = set_time_scale(*world, -1);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("time_scale"), std::string::npos);
}

TEST(BuildWorld, BadScenesNameTheField) {
    SceneDescription scene = sample();
    ColliderOverride tail;
    tail.bone = "Tail";
    tail.radii_m = Vec3(0.1f, 0.1f, 0.1f);
    scene.colliders.push_back(tail);
    auto r = build_world(scene, {});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message.rfind("colliders[0].bone: no bone \"Tail\" in ", 0), 0u) << r.error().message;

    scene = sample();
    scene.characters[0].clip = "Moonwalk";
    r = build_world(scene, {});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message.rfind("characters[0].clip: ", 0), 0u) << r.error().message;

    // A character file of random bytes.
    const fs::path junk = fs::temp_directory_path() / ("drape_scene_test_junk_" + std::to_string(::getpid()) + ".glb");
    {
        std::ofstream out(junk, std::ios::binary);
        std::mt19937 rng(7);
        for (int i = 0; i < 4096; ++i) out.put(static_cast<char>(rng() & 0xff));
    }
    scene = sample();
    scene.characters[0].file = junk;
    r = build_world(scene, {});
    fs::remove(junk);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message.rfind("characters[0].file: ", 0), 0u) << r.error().message;
    EXPECT_EQ(r.error().message.find('\n'), std::string::npos);
}

TEST(ParticleLimit, OneLimitForScenesAndCppBuilders) {
    // A C++ builder refuses an absurd grid with the fields and the limit...
    TubeParams skirt = TubeParams::skirt();
    skirt.warp_lines = 1002;
    skirt.particles_per_line = 1000;
    auto r = validate(skirt, "skirt");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message, "skirt.warp_lines x skirt.particles_per_line: must be at most 250000 particles, got 1002 x 1000 = 1002000");
    TubeParams dress = TubeParams::dress();
    dress.warp_lines = 501;
    dress.particles_per_line = 500;
    EXPECT_FALSE(validate(dress, "dress"));
    // ... and a scene asking for the most particles gets a garment within the same limit
    // (the grid's rounding may not pass it).
    SceneDescription scene = sample();
    scene.garments[0].parameters = {{"particles", double(max_garment_particles)}};
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    const Garment& g = world->registry.get<Garment>(world->garments[0]);
    EXPECT_LE(g.state.x.cols(), max_garment_particles);
    EXPECT_GT(g.state.x.cols(), max_garment_particles * 9 / 10);
}

TEST(BuildWorld, ErrorsFromAFileCarryItsPosition) {
    const fs::path dir = fs::temp_directory_path() / ("drape_scene_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path file = dir / "scene.json";
    std::ofstream(file) << "{\"characters\": [{\"file\": \"" << default_avatar_path().string() << "\"}],\n"
                        << " \"colliders\": [{\"bone\": \"Tail\", \"radii_m\": [0.1, 0.1, 0.1]}]}";
    auto scene = load_scene_file(file);
    ASSERT_TRUE(scene) << scene.error().message;
    auto r = build_world(*scene, {});
    fs::remove_all(dir);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message.rfind(file.string() + ":2:25: colliders[0].bone: no bone \"Tail\"", 0), 0u) << r.error().message;
}

TEST(BuildWorld, ColliderOverridesReshapeAndRemove) {
    SceneDescription scene = sample();
    // The bone that carries the fitted head ellipsoid.
    std::string head_bone;
    {
        auto plain = build_world(scene, {});
        ASSERT_TRUE(plain) << plain.error().message;
        plain->registry.view<EllipsoidCollider>().each([&](Entity, EllipsoidCollider& c) {
            if (c.region == BodyRegion::head)
                head_bone = plain->registry.get<Skeleton>(plain->characters[0]).asset->bone_names.at(c.bone);
        });
        ASSERT_FALSE(head_bone.empty()) << "the avatar has no head ellipsoid";
    }
    ColliderOverride head_override, hips_override;
    head_override.bone = head_bone;
    head_override.remove = true;
    hips_override.bone = "Hips";
    hips_override.radii_m = Vec3(0.2f, 0.15f, 0.16f);
    scene.colliders.push_back(head_override);
    scene.colliders.push_back(hips_override);
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    int hips = 0, head = 0;
    world->registry.view<EllipsoidCollider>().each([&](Entity, EllipsoidCollider& c) {
        if (c.radii_m.isApprox(Vec3(0.2f, 0.15f, 0.16f))) ++hips;
        if (c.region == BodyRegion::head) ++head;
    });
    EXPECT_GE(hips, 1);
    EXPECT_EQ(head, 0);
    for (int frame = 0; frame < 10; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    expect_never_nonfinite(*world);
}

// Property: random garment parameters within the documented ranges give a world that
// steps with finite values, or one error line naming the garment. Bounded: 16 cases.
TEST(BuildWorld, RandomGarmentParametersGiveAWorldOrOneError) {
    std::mt19937 rng(2024);
    int built = 0, rejected = 0;
    for (int i = 0; i < 16; ++i) {
        SceneDescription scene = sample();
        GarmentDescription& g = scene.garments[0];
        g.type = (i % 4 == 3) ? GarmentType::dress : GarmentType::skirt;
        g.model = (i % 2) ? ClothModel::classic : ClothModel::simplified;
        for (const ParameterSpec* spec : scene_garment_parameters()) {
            if (rng() % 3 != 0) continue;
            if (spec->name == "particles" || spec->name == "warp_lines" || spec->name == "particles_per_line") {
                if (spec->name == "particles") g.parameters.push_back({"particles", double(100 + rng() % 1500)});
                continue;  // keep each case small
            }
            const ParameterRange& range = spec->range;
            std::uniform_real_distribution<double> u(range.min, std::min(range.max, range.min + 10.0));
            double v = u(rng);
            if (spec->kind == ParameterKind::integer) v = std::round(v);
            if (range.min_open && v <= range.min) v = range.min + 0.01;
            if (range.max_open && v >= range.max) v = range.max - 0.01;
            g.parameters.push_back({std::string(spec->name), v});
        }
        auto world = build_world(scene, {});
        if (!world) {
            ++rejected;
            EXPECT_EQ(world.error().message.rfind("garments[0]", 0), 0u) << world.error().message;
            EXPECT_EQ(world.error().message.find('\n'), std::string::npos);
            continue;
        }
        ++built;
        for (int frame = 0; frame < 5; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        // The collision step resets a garment that went non-finite, so finite positions
        // alone prove nothing: no value may have gone non-finite and no reset may have run.
        EXPECT_FALSE(has_nonfinite(*world)) << to_json(scene);
        const Garment& garment = world->registry.get<Garment>(world->garments.at(0));
        EXPECT_EQ(garment.counters.non_finite_values, 0u) << to_json(scene);
        EXPECT_EQ(garment.counters.resets, 0u) << to_json(scene);
    }
    // Both outcomes occur among the cases: the property is exercised on both sides.
    EXPECT_GT(built, 0);
    EXPECT_GT(rejected, 0);
}

}  // namespace
}  // namespace drape
