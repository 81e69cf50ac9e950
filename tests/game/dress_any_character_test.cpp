// Dressing characters no one here made, as a new user would through a scene description:
// the third-party characters in ../shared/assets/characters, each in a skirt and in a
// dress. The garment must sit on the body (around its hips), no free particle may end
// inside an ellipsoid it collides with (past its give) nor lie deeper behind the skin
// inside one it leaves out, and nothing may go non-finite; four of the humanoids' six
// garments hold the after-frame contract asked of such characters in every build (the
// other two in the release build only).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <utility>
#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/game/skin_penetration.hpp"
#include "drape/game/stats.hpp"
#include "drape/game/world.hpp"
#include "drape/systems/cloth/body.hpp"
#include "drape/systems/cloth/collision.hpp"
#include "tests/figures.hpp"
#include "tests/game/character_contract.hpp"
#include "tests/shared_assets.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

struct Character {
    const char* file;
    const char* clip;
};

const Character characters[] = {
    {"characters/male_casual/Male_Casual.fbx", "HumanArmature|Man_Walk"},
    {"characters/robot_expressive/RobotExpressive.glb", "Walking"},
    {"characters/rigged_simple/RiggedSimple.glb", ""},
};

// Free particles inside an ellipsoid of the character (1 % inside the surface): those the
// garment collides with, the upper arms (a dress hung from under the arms does not collide
// with them: they hang outside it against the chest), the trunk's thin pieces a built-in
// garment leaves out (TubeParams::thin_trunk_piece_m: they stand between neighbouring
// particles and hold the cloth open), and any other.
struct Inside {
    int collided = 0;     ///< Inside an ellipsoid the garment collides with.
    int upper_arms = 0;   ///< Inside only upper-arm ellipsoids it does not collide with.
    std::vector<std::uint32_t> trunk;  ///< Inside only torso or pelvis ellipsoids it does not collide with (ascending).
    int other = 0;        ///< Inside only other ellipsoids it does not collide with.
};

Inside particles_inside(World& world, const Garment& g) {
    Inside r;
    std::vector<EllipsoidFrame> frames;  // the garment's colliders as the cloth sees them
    update_frames(world.registry, g.body, frames, 1);
    for (Eigen::Index i = 0; i < g.state.x.cols(); ++i) {
        if (g.state.inv_mass[i] == 0) continue;  // pinned to the skin
        bool in_collided = false, in_arm = false, in_trunk = false, in_other = false;
        world.registry.view<EllipsoidCollider>().each([&](Entity e, EllipsoidCollider& c) {
            if (c.character != g.body.character || (c.world.inverse() * g.state.x.col(i)).norm() >= 0.99f) return;
            const auto k = std::find(g.body.colliders.begin(), g.body.colliders.end(), e) - g.body.colliders.begin();
            if (static_cast<std::size_t>(k) < g.body.colliders.size()) {
                // Past its give (a forearm's or a hand's where it meets the hips) by 1 % of its size.
                const EllipsoidFrame& f = frames[static_cast<std::size_t>(k)];
                in_collided = in_collided || depth_past_give(frames, static_cast<std::size_t>(k), g.state.x.col(i)) >
                                                 Real(0.01) * f.radii_m.minCoeff();
            } else if (c.region == BodyRegion::upper_arm) {
                in_arm = true;
            } else if (c.region == BodyRegion::torso || c.region == BodyRegion::pelvis) {
                in_trunk = true;
            } else {
                in_other = true;
            }
        });
        if (in_collided) {
            ++r.collided;
        } else if (in_other) {
            ++r.other;
        } else if (in_trunk) {
            r.trunk.push_back(static_cast<std::uint32_t>(i));
        } else if (in_arm) {
            ++r.upper_arms;
        }
    }
    return r;
}

// `file`'s character walking in place from `start_s` into its clip, in one garment.
SceneDescription walking_in_place(const fs::path& file, GarmentType type, double start_s = 0) {
    SceneDescription scene;
    scene.characters.emplace_back();
    scene.characters[0].file = file;
    scene.characters[0].in_place = true;
    scene.characters[0].start_s = start_s;
    scene.garments.emplace_back();
    scene.garments[0].type = type;
    return scene;
}

void dress_and_walk(const Character& c, GarmentType type) {
    const fs::path file = test::shared_assets() / c.file;
    DRAPE_REQUIRE_SHARED(file);
    SceneDescription scene;
    scene.characters.emplace_back();
    scene.characters[0].file = file;
    scene.characters[0].clip = c.clip;
    scene.garments.emplace_back();
    scene.garments[0].type = type;
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    for (int frame = 0; frame < test::frames(120); ++frame) {
        ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        ASSERT_FALSE(has_nonfinite(*world)) << "frame " << frame;
    }
    if (test::short_form()) return;  // labelled `figures`: the short form runs clean
    const Garment& g = world->registry.get<Garment>(world->garments[0]);
    const Inside inside = particles_inside(*world, g);
    EXPECT_EQ(inside.collided, 0);
    EXPECT_EQ(inside.other, 0);
    // Cloth inside the thin trunk pieces it leaves out lies no deeper behind the skin than the
    // garment elsewhere, where the fit's own ellipsoids stand inside the skin: the pieces let
    // it pass, not sink into the torso. Measured (x86-64-v3, 120 frames): Male_Casual's skirt
    // 3 particles in them, at most 13.0 mm behind the skin against 18.8 mm elsewhere; his dress
    // 23, 15.6 against 20.1 mm; the other garments none.
    const SkinDepths skin = skin_depths(world->registry, g);
    ASSERT_TRUE(skin.measured);
    double in_trunk_m = 0, elsewhere_m = 0;
    for (std::size_t k = 0; k < skin.behind_m.size(); ++k) {
        const bool in_piece = std::binary_search(inside.trunk.begin(), inside.trunk.end(), skin.behind_particles[k]);
        double& deepest = in_piece ? in_trunk_m : elsewhere_m;
        deepest = std::max(deepest, skin.behind_m[k]);
    }
    EXPECT_LE(in_trunk_m, elsewhere_m) << inside.trunk.size() << " particles inside thin trunk pieces left out";
    if (type == GarmentType::skirt) {
        EXPECT_EQ(inside.upper_arms, 0);  // a skirt collides with the whole body
    }
    // On the body: the garment's centre is near its anchor ellipsoid (hips or chest) horizontally.
    ASSERT_GE(g.body.anchor, 0);
    const Vec3 anchor = world->registry.get<EllipsoidCollider>(g.body.colliders.at(static_cast<std::size_t>(g.body.anchor))).world.translation();
    const Vec3 centre = g.state.x.rowwise().mean();
    EXPECT_LT(Vec3(centre.x() - anchor.x(), 0, centre.z() - anchor.z()).norm(), 0.25f);
    // Hanging from its fitting ring: the garment's centre is below its pinned particles.
    Vec3 ring = Vec3::Zero();
    int pinned = 0;
    for (Eigen::Index i = 0; i < g.state.x.cols(); ++i)
        if (g.state.inv_mass[i] == 0) {
            ring += g.state.x.col(i);
            ++pinned;
        }
    ASSERT_GT(pinned, 0);
    EXPECT_LT(centre.y(), ring.y() / Real(pinned));
    // And the contract asked of characters, after every one of the 120 frames.
    test::expect_character_contract(run_stats(*world).garments.at(0));
}

// 300 frames of the walk the importer picks, after every frame: strain p99 <= 10 %, max
// <= 20 %, nothing inside after the frame beyond 2 mm (past a forearm's or a hand's give),
// pins outside. Measured (worst spring, the build scripts/test makes: x86-64-v3, Eigen's
// exact square root, the same bits on Intel and AMD): all six 10.0 %, RobotExpressive's
// skirt with 54 lines round its waist (line_spacing_m) and its dress shortened to clear its
// feet; with the trunk's thin pieces collided (thin_trunk_piece_m 0), Female_Alternative's
// skirt 14.4 % and dress 13.0 %. These walks are chaotic where the cloth is caught: with the
// thin pieces collided and started from 25 points of their clips, Female_Alternative's
// skirt went over 20 % from 1, her dress from 3, Male_Casual's dress from 1, the others from
// none (docs/cloth.md "Reproducibility"; her skirt reached 125 % on an Intel Xeon in a build
// whose square root the CPU approximated).
TEST(DressAnyCharacter, GarmentsHoldTheContractOnTheSharedHumanoids) {
    const Character female{"characters/female_alternative/Female_Alternative.fbx", ""};
    const std::pair<const Character&, GarmentType> cases[] = {{characters[0], GarmentType::skirt},
                                                              {characters[0], GarmentType::dress},
                                                              {characters[1], GarmentType::skirt},
                                                              {characters[1], GarmentType::dress},
                                                              {female, GarmentType::skirt},
                                                              {female, GarmentType::dress}};
    for (const auto& [c, type] : test::cases(cases)) {
        const fs::path file = test::shared_assets() / c.file;
        DRAPE_REQUIRE_SHARED(file);
        SCOPED_TRACE(std::string(c.file) + (type == GarmentType::skirt ? ", skirt" : ", dress"));
        auto world = build_world(walking_in_place(file, type), {});
        ASSERT_TRUE(world) << world.error().message;
        for (int frame = 0; frame < test::frames(300); ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        const GarmentStats g = run_stats(*world).garments.at(0);
        test::expect_character_contract(g);
    }
}

// How many lines a garment gets (line_spacing_m, hem_spacing_leg_widths) does not depend on
// where in the walk it is put on: measured by the width of the legs' level slices at the
// hem's height, a plane through a lifted foot's tip gave Female_Alternative's dress, put on
// 0.375 s into her walk, 264 lines instead of 120 (and tore: 160 %).
TEST(DressAnyCharacter, LinesDoNotDependOnWhereInTheWalkTheGarmentIsPutOn) {
    const Character female{"characters/female_alternative/Female_Alternative.fbx", ""};
    const std::pair<const Character&, GarmentType> cases[] = {{female, GarmentType::dress},
                                                              {female, GarmentType::skirt},
                                                              {characters[1], GarmentType::skirt}};
    for (const auto& [c, type] : cases) {
        const fs::path file = test::shared_assets() / c.file;
        DRAPE_REQUIRE_SHARED(file);
        std::uint32_t first = 0;
        for (const double start_s : {0.0, 0.25, 0.375, 0.625}) {
            SCOPED_TRACE(std::string(c.file) + (type == GarmentType::skirt ? ", skirt" : ", dress") + " from " +
                         std::to_string(start_s) + " s");
            auto world = build_world(walking_in_place(file, type, start_s), {});
            ASSERT_TRUE(world) << world.error().message;
            const std::uint32_t lines = world->registry.get<Garment>(world->garments.at(0)).fabric->warp_lines;
            if (start_s == 0) first = lines;
            EXPECT_EQ(lines, first);
        }
    }
}

// A dress put on Male_Casual a quarter and five eighths of a second into his walk, his hands
// swinging at his sides: its rest shape puts cloth inside a forearm or a hand, which must go
// under the arm, not round it (pushed the shortest way, the cloth wrapped the outside of
// the hand and tore within ten frames: 280 % and 158 %). The first 30 frames.
TEST(DressAnyCharacter, ADressStartedMidStrideHangsUnderTheArms) {
    const fs::path file = test::shared_assets() / characters[0].file;
    DRAPE_REQUIRE_SHARED(file);
    for (const double start_s : {0.25, 0.625}) {
        SCOPED_TRACE("start " + std::to_string(start_s) + " s");
        auto world = build_world(walking_in_place(file, GarmentType::dress, start_s), {});
        ASSERT_TRUE(world) << world.error().message;
        for (int frame = 0; frame < 30; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        test::expect_character_contract(run_stats(*world).garments.at(0));
    }
}

// RobotExpressive's dress put on 0.375 s into its walk starts with its hem across a bent knee
// and falls onto the body over its first frames: with contact repair's larger budget in the
// first step only, a spring at the knee reached 70.2 % in the seventh frame. The larger
// budget lasts the first 1/6 s (garment_step.cpp). The first 30 frames.
TEST(DressAnyCharacter, ADressPutOnMidStrideSettlesOntoAKnee) {
    const fs::path file = test::shared_assets() / characters[1].file;
    DRAPE_REQUIRE_SHARED(file);
    auto world = build_world(walking_in_place(file, GarmentType::dress, 0.375), {});
    ASSERT_TRUE(world) << world.error().message;
    for (int frame = 0; frame < 30; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    test::expect_character_contract(run_stats(*world).garments.at(0));
}

TEST(DressAnyCharacter, MaleCasualInASkirt) { dress_and_walk(characters[0], GarmentType::skirt); }
TEST(DressAnyCharacter, RobotExpressiveInASkirt) { dress_and_walk(characters[1], GarmentType::skirt); }
TEST(DressAnyCharacter, RiggedSimpleInASkirt) { dress_and_walk(characters[2], GarmentType::skirt); }
TEST(DressAnyCharacter, MaleCasualInADress) { dress_and_walk(characters[0], GarmentType::dress); }
TEST(DressAnyCharacter, RobotExpressiveInADress) { dress_and_walk(characters[1], GarmentType::dress); }

}  // namespace
}  // namespace drape
