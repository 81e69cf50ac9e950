// A game's order: spawn a character, attach a garment at once, then step. The character is
// valid before its first step (spawn.hpp): its colliders are placed where the collider
// system would place them, so a garment can be built around them straight away.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/engine/assets/character_import.hpp"
#include "drape/engine/core/scheduler.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/spawn.hpp"
#include "drape/systems/character_systems.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_quality.hpp"
#include "drape/systems/cloth_systems.hpp"
#include "tests/test_paths.hpp"
#include "tests/figures.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

struct Avatar {
    std::shared_ptr<const CharacterAsset> asset;
    CharacterBody body;
};

Avatar load_avatar() {
    const fs::path file = test::source_dir() / "assets/avatar.glb";
    auto asset = import_character(file);
    EXPECT_TRUE(asset) << (asset ? "" : asset.error().message);
    if (!asset) return {};
    auto body = fit_character_body(**asset);
    EXPECT_TRUE(body) << (body ? "" : body.error().message);
    if (!body) return {};
    return {*asset, *body};
}

TEST(SpawnAttachStep, SpawnPlacesTheCollidersWhereTheColliderSystemWould) {
    const Avatar avatar = load_avatar();
    ASSERT_TRUE(avatar.asset);
    Registry spawned;
    const auto a = spawn_character(spawned, avatar.asset, avatar.body);
    ASSERT_TRUE(a) << a.error().message;
    Registry stepped;
    const auto b = spawn_character(stepped, avatar.asset, avatar.body);
    ASSERT_TRUE(b) << b.error().message;
    Scheduler scheduler;
    add_character_systems(scheduler);
    scheduler.run_phase(stepped, Phase::skinning, FrameContext{.fixed_dt_s = 1.0 / 60.0});

    const auto placed = colliders_of(spawned, *a);
    const auto updated = colliders_of(stepped, *b);
    ASSERT_EQ(placed.size(), updated.size());
    ASSERT_FALSE(placed.empty());
    for (std::size_t i = 0; i < placed.size(); ++i) {
        const EllipsoidCollider& p = spawned.get<EllipsoidCollider>(placed[i]);
        const EllipsoidCollider& u = stepped.get<EllipsoidCollider>(updated[i]);
        EXPECT_TRUE(p.placed);
        EXPECT_FALSE(p.initialised);  // velocities start with the first step
        EXPECT_TRUE(p.world.matrix().isApprox(u.world.matrix(), 1e-6f)) << "collider " << i;
    }
}

// Labelled `figures`: the short form asserts that it plays clean, not the strain.
TEST(SpawnAttachStep, ASkirtAttachedRightAfterSpawnPlaysWithinTheContract) {
    const Avatar avatar = load_avatar();
    ASSERT_TRUE(avatar.asset);
    Registry registry;
    const auto character = spawn_character(registry, avatar.asset, avatar.body);
    ASSERT_TRUE(character) << character.error().message;
    const auto garment = attach_skirt(registry, *character, TubeParams::skirt());
    ASSERT_TRUE(garment) << garment.error().message;

    Scheduler scheduler;
    add_character_systems(scheduler);
    add_cloth_systems(scheduler);
    Real strain_max = 0;
    Real penetration_max = 0;
    for (int frame = 0; frame < test::frames(60); ++frame) {
        const auto report = scheduler.tick(registry, 1.0 / 60.0);
        ASSERT_TRUE(report) << report.error().message;
        const Garment& g = registry.get<Garment>(*garment);
        ASSERT_TRUE(g.state.x.allFinite() && g.state.v.allFinite()) << "frame " << frame;
        const GarmentQuality q = measure_garment(registry, g);
        EXPECT_EQ(q.nonfinite, 0u);
        strain_max = std::max(strain_max, q.strain_max);
        penetration_max = std::max(penetration_max, q.penetration_m);
    }
    EXPECT_GT(registry.get<Garment>(*garment).counters.collision_tests, 0u);  // the cloth ran
    if (test::short_form()) return;
    EXPECT_LE(strain_max, 0.20f);        // the contract's largest strain
    EXPECT_LE(penetration_max, 0.002f);  // and depth inside the body after the frame
}

}  // namespace
}  // namespace drape
