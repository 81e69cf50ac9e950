// Every third-party character in ../shared/assets/characters imports with its clips,
// bones and normalised weights, and gets fitted ellipsoids that cover it. These files
// live outside the project; without them the tests skip and say so, except under CI.
#include <gtest/gtest.h>

#include <filesystem>

#include "drape/engine/assets/character_import.hpp"
#include "tests/character/leg_expectations.hpp"
#include "tests/shared_assets.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/character_report.hpp"
#include "drape/systems/character/pose.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

std::filesystem::path shared(const char* relative) { return test::shared_assets() / relative; }

#define REQUIRE_SHARED(path) DRAPE_REQUIRE_SHARED(path)

struct Expect {
    const char* file;
    std::size_t clips;
    const char* walk;
    double walk_s;
    int min_skin_bones;
    bool human;
};

class SharedCharacter : public ::testing::TestWithParam<Expect> {};

TEST_P(SharedCharacter, ImportsWithClipsBonesNormalisedWeightsAndCoveringEllipsoids) {
    const Expect& e = GetParam();
    const auto path = shared(e.file);
    REQUIRE_SHARED(path);
    auto r = import_character(path);
    ASSERT_TRUE(r) << r.error().message;
    const CharacterAsset& c = **r;
    EXPECT_EQ(c.clips.size(), e.clips);
    auto walk = find_clip(c, e.walk);
    ASSERT_TRUE(walk) << walk.error().message;
    if (const auto bar = std::string(e.walk).rfind('|'); bar != std::string::npos) {
        EXPECT_EQ(find_clip(c, std::string(e.walk).substr(bar + 1)).value(), *walk);  // "Man_Walk"
    }
    ASSERT_TRUE(walk) << walk.error().message;
    EXPECT_NEAR(c.clips[*walk]->duration_s, e.walk_s, 0.01);
    EXPECT_GE(c.skin_bones, e.min_skin_bones);
    const MeshAsset& m = *c.mesh;
    for (Eigen::Index j = 0; j < m.bone_weights.cols(); ++j) ASSERT_NEAR(m.bone_weights.col(j).sum(), 1.0f, 1e-5f) << j;
    ASSERT_TRUE(m.bind_positions.allFinite());

    EXPECT_GE(c.height_m, e.human ? 1.5f : 0.1f);
    EXPECT_LE(c.height_m, e.human ? 2.0f : 3.0f);
    const auto fitted = fit_character_body(c);
    ASSERT_TRUE(fitted) << fitted.error().message;
    const CharacterBody& body = *fitted;
    ASSERT_FALSE(body.ellipsoids.empty());
    std::vector<Affine3> global, skinning;
    compose_pose(*c.skeleton, c.skeleton->rest_local, global);
    skinning_matrices(*c.skeleton, global, skinning);
    Matrix3X p, n;
    skin_mesh(m, skinning, Affine3::Identity(), p, n);
    const CoverageReport report = measure_coverage(body.ellipsoids, global, p, n, m.indices);
    // A garment takes at most 64 colliders; the fitted pieces keep to the fit's budget.
    EXPECT_LE(body.ellipsoids.size() - static_cast<std::size_t>(std::count_if(body.ellipsoids.begin(), body.ellipsoids.end(), test::is_knee_sphere)),
              test::fitted_budget(body, FitOptions{}));
    EXPECT_LE(body.ellipsoids.size(), 64u);
    EXPECT_GE(report.coverage, 0.95) << e.file << ": largest gap " << report.max_gap_m << " m";
    if (e.human) {
        // The target, 99 % of the skin within 1 cm and a p95 bulge of 2 cm, is met where the
        // legs are fitted tight (SharedCharacterFit.TheHumansGetTightLegsAndTheFitHugsTheWholeBody);
        // where the tight fit misses it the legs keep their bounding ellipsoids (4.5 cm and
        // 97.1 % on RobotExpressive; with bounding legs 5.5 cm on Male_Casual, 6.1 cm and
        // 98.9 % on Female_Alternative). This bound guards the rest of the fit: a trunk or
        // arm piece floating off the body breaks it.
        EXPECT_LE(report.p95_bulge_m, 0.08) << e.file << ": max bulge " << report.max_bulge_m << " m";
        EXPECT_GE(body.ellipsoids.size(), 10u);
        EXPECT_GE(body.hip_bone, 0);
        EXPECT_TRUE(std::any_of(body.ellipsoids.begin(), body.ellipsoids.end(), [](auto& s) { return s.region == BodyRegion::pelvis; }));
        // One ellipsoid per hand and per foot: fingers merge, left and right do not.
        auto count = [&](BodyRegion r) { return std::count_if(body.ellipsoids.begin(), body.ellipsoids.end(), [&](auto& s) { return s.region == r; }); };
        EXPECT_EQ(count(BodyRegion::hand), 2);
        EXPECT_EQ(count(BodyRegion::foot), 2);
        test::expect_legs(body, FitOptions{});
        // Standing on the ground, Y up: feet near the bottom, head at the top.
        EXPECT_NEAR(p.row(1).minCoeff(), 0.0f, 0.05f);
    }
}

INSTANTIATE_TEST_SUITE_P(
    Characters, SharedCharacter,
    ::testing::Values(Expect{"characters/male_casual/Male_Casual.fbx", 11, "HumanArmature|Man_Walk", 1.04, 25, true},
                      Expect{"characters/female_alternative/Female_Alternative.fbx", 11, "HumanArmature|Female_Walk", 1.04, 25, true},
                      Expect{"characters/robot_expressive/RobotExpressive.glb", 14, "Walking", 0.96, 20, true},
                      Expect{"characters/rigged_simple/RiggedSimple.glb", 1, "0", 2.08, 2, false}),
    [](const auto& info) { return std::filesystem::path(info.param.file).stem().string(); });

// By default the legs are fitted tight where the fit then covers the skin
// (LegFit::automatic): on the human characters it does, and the whole body is hugged to
// the targets.
TEST(SharedCharacterFit, TheHumansGetTightLegsAndTheFitHugsTheWholeBody) {
    for (const char* file : {"characters/male_casual/Male_Casual.fbx", "characters/female_alternative/Female_Alternative.fbx"}) {
        SCOPED_TRACE(file);
        const auto path = shared(file);
        REQUIRE_SHARED(path);
        auto r = import_character(path);
        ASSERT_TRUE(r) << r.error().message;
        const FitOptions options;
        const auto body = fit_character_body(**r, options);
        ASSERT_TRUE(body) << body.error().message;
        EXPECT_EQ(body->legs, LegFit::tight);
        const CoverageReport report = rest_pose_coverage(**r, *body);
        EXPECT_GE(report.coverage, 0.99) << "largest gap " << report.max_gap_m << " m";
        EXPECT_LE(report.p95_bulge_m, 0.02) << "max bulge " << report.max_bulge_m << " m";
        EXPECT_TRUE(meets_fit_targets(report, options));
        test::expect_legs(*body, options);
    }
}

// Where the tight legs leave the skin short of the coverage target (RobotExpressive: plates
// and ball joints, 97 % either way), the default keeps the legs' bounding ellipsoids, the
// same shapes as asking for them.
TEST(SharedCharacterFit, WhereTightLegsMissTheTargetsTheLegsAreBounded) {
    const auto path = shared("characters/robot_expressive/RobotExpressive.glb");
    REQUIRE_SHARED(path);
    auto r = import_character(path);
    ASSERT_TRUE(r) << r.error().message;
    FitOptions tight;
    tight.legs = LegFit::tight;
    const auto tight_body = fit_character_body(**r, tight);
    ASSERT_TRUE(tight_body) << tight_body.error().message;
    EXPECT_FALSE(covers_skin(rest_pose_coverage(**r, *tight_body), tight));
    FitOptions bounding;
    bounding.legs = LegFit::bounding;
    const auto automatic = fit_character_body(**r), bounded = fit_character_body(**r, bounding);
    ASSERT_TRUE(automatic && bounded);
    EXPECT_EQ(automatic->legs, LegFit::bounding);
    ASSERT_EQ(automatic->ellipsoids.size(), bounded->ellipsoids.size());
    for (std::size_t i = 0; i < automatic->ellipsoids.size(); ++i) {
        EXPECT_EQ(automatic->ellipsoids[i].bone, bounded->ellipsoids[i].bone) << i;
        EXPECT_EQ(automatic->ellipsoids[i].center, bounded->ellipsoids[i].center) << i;
        EXPECT_EQ(automatic->ellipsoids[i].radii_m, bounded->ellipsoids[i].radii_m) << i;
    }
}

TEST(SharedCharacterFbx, BindPoseIsAWideTPoseWhileTheRestPoseHasArmsDown) {
    const auto path = shared("characters/male_casual/Male_Casual.fbx");
    REQUIRE_SHARED(path);
    auto r = import_character(path);
    ASSERT_TRUE(r) << r.error().message;
    const CharacterAsset& c = **r;
    std::vector<Affine3> global, skinning;
    compose_pose(*c.skeleton, c.skeleton->rest_local, global);
    skinning_matrices(*c.skeleton, global, skinning);
    Matrix3X rest;
    skin_positions(*c.mesh, skinning, Affine3::Identity(), rest);
    const Real bind_width = c.mesh->bind_positions.row(0).maxCoeff() - c.mesh->bind_positions.row(0).minCoeff();
    const Real rest_width = rest.row(0).maxCoeff() - rest.row(0).minCoeff();
    EXPECT_GT(bind_width, 1.5f * rest_width) << bind_width << " vs " << rest_width;
}

TEST(SharedCharacterGltf, RigidlyParentedMeshesBecomeSkinnedToTheirBone) {
    const auto path = shared("characters/robot_expressive/RobotExpressive.glb");
    REQUIRE_SHARED(path);
    auto r = import_character(path);
    ASSERT_TRUE(r) << r.error().message;
    const CharacterAsset& c = **r;
    EXPECT_EQ(c.meshes.size(), 19u);
    EXPECT_EQ(std::count_if(c.meshes.begin(), c.meshes.end(), [](auto& m) { return m.rigid; }), 15);
    // A rigid foot follows its bone: playing the walk moves its vertices.
    auto walk = find_clip(c, "Walking");
    ASSERT_TRUE(walk);
    std::vector<Affine3> local, global, skinning;
    Matrix3X a, b;
    for (double t : {0.0, 0.4}) {
        sample_clip(*c.clips[*walk], *c.skeleton, t, true, local);
        compose_pose(*c.skeleton, local, global);
        skinning_matrices(*c.skeleton, global, skinning);
        skin_positions(*c.mesh, skinning, Affine3::Identity(), t == 0 ? a : b);
    }
    EXPECT_GT((a - b).colwise().norm().maxCoeff(), 0.05f);
    EXPECT_TRUE(b.allFinite());
}

}  // namespace
}  // namespace drape
