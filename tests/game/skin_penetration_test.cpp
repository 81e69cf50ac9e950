// Cloth behind the skin mesh (game/skin_penetration.hpp): the figure of what a user would
// see through the body, measured on the mesh, not on the ellipsoids the cloth collides with.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/skin_penetration.hpp"
#include "drape/game/world.hpp"
#include "tests/shared_assets.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

World skirt_on(const fs::path& file, bool measure) {
    SceneDescription scene = sample_scene();
    scene.characters.at(0).file = file;
    scene.characters.at(0).clip.clear();  // the character's own walk
    WorldOptions options;
    options.skin_penetration = measure;
    auto world = build_world(scene, options);
    EXPECT_TRUE(world) << (world ? "" : world.error().message);
    return world ? std::move(*world) : World();
}

// The centre of the character's first ellipsoid of a region, in the world.
Vec3 centre_of(World& world, BodyRegion region) {
    Vec3 out = Vec3::Constant(std::numeric_limits<Real>::quiet_NaN());
    world.registry.view<EllipsoidCollider>().each([&](Entity, EllipsoidCollider& c) {
        if (c.region == region && !out.allFinite()) out = c.world.translation();
    });
    return out;
}

// A free particle moved into the middle of the pelvis lies behind the skin, about as deep
// as the pelvis is; one moved a metre out in front does not; one beside a foot, outside it
// (Male_Casual's shoes are an open shell turned in at their rims) does not either.
TEST(SkinPenetration, AParticleInTheBodyIsBehindTheSkinAndOneBesideItIsNot) {
    const fs::path male_casual = test::shared_assets() / "characters/male_casual/Male_Casual.fbx";
    for (const fs::path& file : {fs::path(sample_scene().characters.at(0).file), male_casual}) {
        if (file == male_casual) DRAPE_REQUIRE_SHARED(file);
        SCOPED_TRACE(file.string());
        World world = skirt_on(file, false);
        ASSERT_FALSE(world.garments.empty());
        ASSERT_TRUE(step_world(world, 1.0 / 60.0));
        Garment& g = world.registry.get<Garment>(world.garments.at(0));
        Eigen::Index free = 0;
        while (g.state.inv_mass[free] == 0) ++free;
        const SkinDepths before = skin_depths(world.registry, g);
        ASSERT_TRUE(before.measured);

        const Vec3 pelvis = centre_of(world, BodyRegion::pelvis);
        ASSERT_TRUE(pelvis.allFinite());
        g.state.x.col(free) = pelvis;
        const SkinDepths inside = skin_depths(world.registry, g);
        ASSERT_EQ(inside.behind_m.size(), before.behind_m.size() + 1) << "the particle in the pelvis is not behind the skin";
        EXPECT_GT(*std::max_element(inside.behind_m.begin(), inside.behind_m.end()), 0.05);

        g.state.x.col(free) = pelvis + Vec3(0, 0, 1);
        EXPECT_EQ(skin_depths(world.registry, g).behind_m.size(), before.behind_m.size());

        // Around the feet, every point 8 cm or more outside every ellipsoid (the fit lets
        // no skin stand out that far) is outside the skin.
        const Vec3 foot = centre_of(world, BodyRegion::foot);
        ASSERT_TRUE(foot.allFinite());
        std::vector<const EllipsoidCollider*> colliders;
        world.registry.view<EllipsoidCollider>().each([&](Entity, EllipsoidCollider& c) { colliders.push_back(&c); });
        const auto far_from_body = [&](const Vec3& q) {
            for (const EllipsoidCollider* c : colliders) {
                const Vec3 radii = c->world.linear().colwise().norm().transpose().array() + Real(0.08);
                const Vec3 y = (c->world_rotation.conjugate() * (q - c->world.translation())).cwiseQuotient(radii);
                if (y.norm() < 1) return false;
            }
            return true;
        };
        std::vector<Vec3> probes;
        for (Real dx = -0.4f; dx <= 0.4f; dx += 0.04f)
            for (Real dz = -0.4f; dz <= 0.4f; dz += 0.04f)
                for (Real y = 0.02f; y <= 0.4f; y += 0.04f)
                    if (const Vec3 q(foot.x() + dx, y, foot.z() + dz); far_from_body(q)) probes.push_back(q);
        // Every free particle a probe at once, as many rounds as it takes.
        const int tried = static_cast<int>(probes.size());
        int behind = 0;
        while (!probes.empty()) {
            for (Eigen::Index p = 0; p < g.state.x.cols(); ++p) {
                if (g.state.inv_mass[p] == 0) continue;
                g.state.x.col(p) = probes.empty() ? Vec3(pelvis + Vec3(0, 0, 1)) : probes.back();
                if (!probes.empty()) probes.pop_back();
            }
            behind += static_cast<int>(skin_depths(world.registry, g).behind_m.size());
        }
        EXPECT_GT(tried, 100);
        EXPECT_EQ(behind, 0) << "of " << tried << " points around the feet, outside the body";
    }
}

TEST(SkinPenetration, IsInTheRunStatsOnlyWhenMeasured) {
    for (const bool measure : {false, true}) {
        World world = skirt_on(sample_scene().characters.at(0).file, measure);
        for (int frame = 0; frame < 30; ++frame) ASSERT_TRUE(step_world(world, 1.0 / 60.0));
        const GarmentStats g = run_stats(world).garments.at(0);
        EXPECT_EQ(g.skin_measured, measure);
        if (!measure) continue;
        EXPECT_GE(g.skin_penetration_share, 0.0);
        EXPECT_LE(g.skin_penetration_share, 1.0);
        EXPECT_LE(g.skin_penetration_p99_m, g.skin_penetration_max_m);
        EXPECT_LT(g.skin_penetration_max_m, 0.05) << "the default avatar's skirt lies more than 5 cm inside its skin";
    }
}

}  // namespace
}  // namespace drape
