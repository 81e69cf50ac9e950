// Crowds: a headless world skins no mesh vertex (the cloth follows the bones); characters
// are posed and their colliders moved in parallel with the same bytes on one or two
// threads; `start_s` puts walkers on different phases; the crowd scene plays headless.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <vector>

#include "drape/components/animation_player.hpp"
#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/game/asset_paths.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/scene_file.hpp"
#include "drape/game/world.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

bool avatar_present() { return fs::exists(sample_scene().characters.at(0).file); }

/// The sample walker `count` times in a row, each `phase_s` further into its clip.
SceneDescription walkers(int count, double phase_s, int threads) {
    SceneDescription scene = sample_scene();
    const CharacterDescription walker = scene.characters.at(0);
    const GarmentDescription skirt = scene.garments.at(0);
    scene.characters.clear();
    scene.garments.clear();
    for (int i = 0; i < count; ++i) {
        CharacterDescription c = walker;
        c.position_m = Vec3(Real(1.5) * Real(i), 0, 0);
        c.start_s = phase_s * i;
        scene.characters.push_back(c);
        GarmentDescription g = skirt;
        g.character = i;
        scene.garments.push_back(g);
    }
    scene.solver.threads = threads;
    return scene;
}

template <class T>
void append_bytes(std::vector<unsigned char>& out, const T* data, std::size_t count) {
    const auto* p = reinterpret_cast<const unsigned char*>(data);
    out.insert(out.end(), p, p + sizeof(T) * count);
}

/// Poses, collider frames and garment particles of a world, as raw bytes.
std::vector<unsigned char> world_bytes(World& world) {
    std::vector<unsigned char> bytes;
    for (Entity e : world.characters) {
        const Skeleton& s = world.registry.get<Skeleton>(e);
        for (const Affine3& m : s.global) append_bytes(bytes, m.data(), 16);
        for (const Affine3& m : s.skinning) append_bytes(bytes, m.data(), 16);
    }
    world.registry.view<EllipsoidCollider>().each([&](Entity, EllipsoidCollider& c) {
        append_bytes(bytes, c.world.data(), 16);
        append_bytes(bytes, c.velocity_m_s.data(), 3);
        append_bytes(bytes, c.acceleration_m_s2.data(), 3);
        append_bytes(bytes, c.angular_velocity_rad_s.data(), 3);
    });
    for (Entity e : world.garments) {
        const Garment& g = world.registry.get<Garment>(e);
        append_bytes(bytes, g.state.x.data(), static_cast<std::size_t>(g.state.x.size()));
        append_bytes(bytes, g.state.v.data(), static_cast<std::size_t>(g.state.v.size()));
    }
    return bytes;
}

std::vector<unsigned char> run(const SceneDescription& scene, int frames) {
    auto world = build_world(scene, {});
    if (!world) {
        ADD_FAILURE() << world.error().message;
        return {};
    }
    for (int f = 0; f < frames; ++f)
        if (auto r = step_world(*world, 1.0 / 60.0); !r) {
            ADD_FAILURE() << r.error().message;
            return {};
        }
    return world_bytes(*world);
}

TEST(Crowd, HeadlessWorldSkinsNoMeshVertex) {
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
    auto world = build_world(walkers(3, 0.3, 0), {});
    ASSERT_TRUE(world) << world.error().message;
    std::vector<std::uint64_t> at_start;
    for (Entity e : world->characters) at_start.push_back(world->registry.get<SkinnedMesh>(e).skinned_vertices);
    const Affine3 first_pose = world->registry.get<Skeleton>(world->characters[0]).global.at(1);
    for (int f = 0; f < 30; ++f) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));

    for (std::size_t i = 0; i < world->characters.size(); ++i)
        EXPECT_EQ(world->registry.get<SkinnedMesh>(world->characters[i]).skinned_vertices, at_start[i])
            << "character " << i << " was skinned in a headless world";
    for (Phase phase : {Phase::animation, Phase::skinning, Phase::simulation, Phase::render})
        for (const std::string& name : world->scheduler.system_names(phase)) {
            EXPECT_NE(name, "skinning");
            EXPECT_NE(name, "skin_cover");
            EXPECT_NE(name, "garment_surface");
        }
    // The bodies moved all the same: the poses advanced and the garments followed them.
    EXPECT_FALSE(world->registry.get<Skeleton>(world->characters[0]).global.at(1).isApprox(first_pose, 1e-6f));
    EXPECT_FALSE(has_nonfinite(*world));
    const RunStats stats = run_stats(*world);
    for (const SystemStats& s : stats.systems) {
        if (s.name == "animation" || s.name == "colliders") {
            EXPECT_EQ(s.runs, 30u) << s.name;
        }
    }
}

TEST(Crowd, OneOrTwoThreadsGiveIdenticalBytes) {
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
    const auto one = run(walkers(6, 0.17, 1), 45);
    const auto two = run(walkers(6, 0.17, 2), 45);
    ASSERT_FALSE(one.empty());
    EXPECT_EQ(one.size(), two.size());
    EXPECT_TRUE(one == two) << "six walkers differ between one and two worker threads";
}

TEST(Crowd, AGarmentStepsTheSameWhoeverElseIsInTheScene) {
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
    // Neighbours on other phases need other substep counts at other times; the first
    // walker's skirt takes its own.
    auto alone = build_world(walkers(1, 0.0, 0), {});
    auto crowd = build_world(walkers(4, 0.29, 0), {});
    ASSERT_TRUE(alone && crowd);
    bool substeps_differed = false;
    for (int f = 0; f < 60; ++f) {
        ASSERT_TRUE(step_world(*alone, 1.0 / 60.0));
        ASSERT_TRUE(step_world(*crowd, 1.0 / 60.0));
        for (Entity e : crowd->garments)
            substeps_differed |= crowd->registry.get<Garment>(e).counters.substeps !=
                                 crowd->registry.get<Garment>(crowd->garments[0]).counters.substeps;
    }
    EXPECT_TRUE(substeps_differed) << "the walkers never needed different substeps: the test shows nothing";
    const Garment& a = alone->registry.get<Garment>(alone->garments[0]);
    const Garment& b = crowd->registry.get<Garment>(crowd->garments[0]);
    EXPECT_TRUE(a.state.x == b.state.x && a.state.v == b.state.v);
}

TEST(Crowd, StartTimePutsWalkersOnDifferentPhases) {
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
    auto world = build_world(walkers(2, 0.4, 0), {});
    ASSERT_TRUE(world) << world.error().message;
    const auto& a = world->registry.get<AnimationPlayer>(world->characters[0]);
    const auto& b = world->registry.get<AnimationPlayer>(world->characters[1]);
    EXPECT_DOUBLE_EQ(a.time_s, 0.0);
    EXPECT_NEAR(b.time_s, 0.4, 1e-9);
    // The same clip at another time: another pose of the legs, relative to each root.
    const Skeleton& sa = world->registry.get<Skeleton>(world->characters[0]);
    const Skeleton& sb = world->registry.get<Skeleton>(world->characters[1]);
    Real largest = 0;
    for (std::size_t bone = 0; bone < sa.global.size(); ++bone)
        largest = std::max(largest, (sa.global[bone].linear() - sb.global[bone].linear()).cwiseAbs().maxCoeff());
    EXPECT_GT(largest, 0.05f);
}

TEST(Crowd, StartTimeIsReadAndWrittenBySceneFiles) {
    SceneDescription scene = walkers(2, 0.25, 0);
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
    auto parsed = parse_scene(to_json(scene), "", {});
    ASSERT_TRUE(parsed) << parsed.error().message;
    EXPECT_DOUBLE_EQ(parsed->characters.at(1).start_s, 0.25);
    scene.characters[1].start_s = -1;
    auto bad = validate(scene);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("characters[1].start_s"), std::string::npos) << bad.error().message;
}

TEST(Crowd, SceneFilePlaysHeadless) {
    auto scene = load_scene_file(asset_dir() / "scenes" / "crowd.json");
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_GE(scene->characters.size(), 20u);
    EXPECT_EQ(scene->garments.size(), scene->characters.size());
    bool idle = false, walk = false, phases = false;
    for (const CharacterDescription& c : scene->characters) {
        idle |= c.clip == "Idle";
        walk |= c.clip == "Walk";
        phases |= c.start_s != scene->characters.front().start_s;
    }
    EXPECT_TRUE(idle && walk && phases) << "the crowd mixes clips and phases";
    auto world = build_world(*scene, {});
    ASSERT_TRUE(world) << world.error().message;
    for (int f = 0; f < 20; ++f) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    EXPECT_FALSE(has_nonfinite(*world));
    EXPECT_EQ(world->teleports->teleports, 0u);
}

}  // namespace
}  // namespace drape
