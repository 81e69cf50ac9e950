// The default avatar (game/avatar_generator.hpp): deterministic, the committed file is the
// generator's output, a plausible body and walk, and it loads through the same import path
// as any other character with fitted ellipsoids that cover it.
#include "drape/game/avatar_generator.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/stats.hpp"
#include "drape/game/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <utility>

#include "drape/components/garment.hpp"
#include "drape/engine/assets/character_import.hpp"
#include "drape/engine/assets/skinning.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/character_report.hpp"
#include "drape/systems/character/pose.hpp"
#include "tests/character/leg_expectations.hpp"
#include "tests/figures.hpp"
#include "tests/game/character_contract.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

const std::filesystem::path committed_avatar = test::source_dir() / "assets" / "avatar.glb";

// Generating takes a moment: share one model and one byte string between the tests.
const AvatarModel& avatar() {
    static const AvatarModel model = make_default_avatar();
    return model;
}
const std::vector<std::uint8_t>& avatar_bytes() {
    static const std::vector<std::uint8_t> bytes = [] {
        auto r = default_avatar_glb();
        EXPECT_TRUE(r) << (r ? "" : r.error().message);
        return r ? *r : std::vector<std::uint8_t>{};
    }();
    return bytes;
}

std::vector<std::uint8_t> read_file(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

Eigen::Vector3d vertex(const AvatarModel& m, std::uint32_t i) { return m.positions.col(i).cast<double>(); }

TEST(DefaultAvatar, GenerationIsDeterministic) {
    const auto again = default_avatar_glb();
    ASSERT_TRUE(again) << again.error().message;
    ASSERT_FALSE(avatar_bytes().empty());
    EXPECT_TRUE(*again == avatar_bytes()) << "two generations gave different bytes";
}

TEST(DefaultAvatar, CommittedFileIsTheGeneratorsOutput) {
    ASSERT_TRUE(std::filesystem::exists(committed_avatar)) << committed_avatar << " is missing: run `drape make-avatar`";
    const std::vector<std::uint8_t> committed = read_file(committed_avatar);
    ASSERT_FALSE(avatar_bytes().empty());
    EXPECT_EQ(committed.size(), avatar_bytes().size());
    EXPECT_TRUE(committed == avatar_bytes())
        << committed_avatar << " differs from the generator's output: run `drape make-avatar --overwrite` and commit it";
}

TEST(DefaultAvatar, HasAFewThousandTrianglesAndAboutTwentyFiveBones) {
    const AvatarModel& m = avatar();
    EXPECT_GE(m.triangle_count(), 5000u);
    EXPECT_LE(m.triangle_count(), 20000u);
    EXPECT_GE(m.bones.size(), 20u);
    EXPECT_LE(m.bones.size(), 30u);
    for (const char* name : {"Hips", "Spine", "Spine1", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm",
                             "LeftForeArm", "LeftHand", "RightArm", "RightHand", "LeftUpLeg", "LeftLeg",
                             "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg", "RightFoot", "RightToeBase"})
        EXPECT_GE(m.find_bone(name), 0) << name;
    for (std::size_t b = 0; b < m.bones.size(); ++b) EXPECT_LT(m.bones[b].parent, static_cast<int>(b)) << m.bones[b].name;
}

TEST(DefaultAvatar, StandsAboutOneSeventyFiveTallOnTheFloor) {
    const AvatarModel& m = avatar();
    const Vec3 low = m.positions.rowwise().minCoeff(), high = m.positions.rowwise().maxCoeff();
    EXPECT_NEAR(high.y() - low.y(), 1.75f, 0.02f);
    EXPECT_NEAR(low.y(), 0.0f, 0.005f);
    // Left-right symmetric about x = 0.
    EXPECT_NEAR(low.x(), -high.x(), 0.005f);
    // Scaling the options scales the body.
    AvatarOptions small;
    small.height_m = 1.6;
    const AvatarModel s = make_default_avatar(small);
    EXPECT_NEAR(s.positions.row(1).maxCoeff() - s.positions.row(1).minCoeff(), 1.6f, 0.02f);
}

TEST(DefaultAvatar, MeshIsClosedAndWoundOutwards) {
    const AvatarModel& m = avatar();
    // Every edge has a twin running the other way: no holes, consistent winding.
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (std::size_t t = 0; t < m.indices.size(); t += 3)
        for (int e = 0; e < 3; ++e) ++edges[{m.indices[t + e], m.indices[t + (e + 1) % 3]}];
    std::size_t open = 0;
    for (const auto& [edge, count] : edges) open += edges.count({edge.second, edge.first}) == 0;
    EXPECT_EQ(open, 0u);
    // Positive enclosed volume of a human's order (60-90 litres for 1.75 m), and the
    // vertex normals agree with the faces around them.
    double volume = 0;
    std::size_t agreeing = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const auto a = vertex(m, m.indices[t]), b = vertex(m, m.indices[t + 1]), c = vertex(m, m.indices[t + 2]);
        volume += a.dot(b.cross(c)) / 6.0;
        const Eigen::Vector3d face = (b - a).cross(c - a);
        agreeing += face.dot(m.normals.col(m.indices[t]).cast<double>()) > 0;
    }
    EXPECT_GT(volume, 0.045);
    EXPECT_LT(volume, 0.095);
    EXPECT_GE(double(agreeing) / double(m.triangle_count()), 0.99);
    for (Eigen::Index v = 0; v < m.normals.cols(); ++v) ASSERT_NEAR(m.normals.col(v).norm(), 1.0f, 1e-4f) << v;
}

TEST(DefaultAvatar, WeightsAreNormalisedWithAtMostFourInfluences) {
    const AvatarModel& m = avatar();
    ASSERT_EQ(m.bone_weights.cols(), m.positions.cols());
    for (Eigen::Index v = 0; v < m.bone_weights.cols(); ++v) {
        ASSERT_NEAR(m.bone_weights.col(v).sum(), 1.0f, 1e-5f) << v;
        ASSERT_GE(m.bone_weights.col(v).minCoeff(), 0.0f) << v;
        ASSERT_GE(m.bone_indices.col(v).minCoeff(), 0) << v;
        ASSERT_LT(m.bone_indices.col(v).maxCoeff(), static_cast<int>(m.bones.size())) << v;
    }
}

// Skin weights fall off smoothly: around each knee, elbow and hip joint some vertices are
// shared between the two bones (no hard seam), while mid-bone vertices follow one bone.
TEST(DefaultAvatar, JointsBlendBetweenTheirTwoBones) {
    const AvatarModel& m = avatar();
    auto weight = [&](Eigen::Index v, int bone) {
        for (int slot = 0; slot < 4; ++slot)
            if (m.bone_indices(slot, v) == bone) return double(m.bone_weights(slot, v));
        return 0.0;
    };
    for (const auto& [parent_name, child_name] : std::vector<std::pair<const char*, const char*>>{
             {"LeftUpLeg", "LeftLeg"}, {"RightUpLeg", "RightLeg"}, {"LeftArm", "LeftForeArm"},
             {"RightArm", "RightForeArm"}, {"Hips", "LeftUpLeg"}, {"Neck", "Head"}}) {
        const int parent = m.find_bone(parent_name), child = m.find_bone(child_name);
        ASSERT_GE(parent, 0);
        ASSERT_GE(child, 0);
        std::size_t shared = 0;
        for (Eigen::Index v = 0; v < m.positions.cols(); ++v)
            shared += weight(v, parent) >= 0.25 && weight(v, child) >= 0.25;
        EXPECT_GE(shared, 10u) << parent_name << " / " << child_name;
    }
    // Halfway down the thigh, the skin follows the thigh alone.
    const int thigh = m.find_bone("LeftUpLeg"), knee = m.find_bone("LeftLeg");
    const double mid_y = 0.5 * (m.bones[std::size_t(thigh)].joint_m.y() + m.bones[std::size_t(knee)].joint_m.y());
    std::size_t checked = 0;
    for (Eigen::Index v = 0; v < m.positions.cols(); ++v)
        if (std::abs(m.positions(1, v) - mid_y) < 0.01 && m.positions(0, v) > 0.03 && m.positions(0, v) < 0.25) {
            EXPECT_GT(weight(v, thigh), 0.99) << "vertex " << v;
            ++checked;
        }
    EXPECT_GT(checked, 5u);
}

// The A-pose keeps the hands clear of the hips and thighs (a dress hangs between them).
TEST(DefaultAvatar, HandsHangClearOfTheBody) {
    const AvatarModel& m = avatar();
    std::vector<int> dominant(std::size_t(m.positions.cols()));
    for (Eigen::Index v = 0; v < m.positions.cols(); ++v) {
        Eigen::Index slot;
        m.bone_weights.col(v).maxCoeff(&slot);
        dominant[std::size_t(v)] = m.bone_indices(slot, v);
    }
    const std::set<int> hands{m.find_bone("LeftHand"), m.find_bone("RightHand")};
    const std::set<int> hips_and_thighs{m.find_bone("Hips"), m.find_bone("LeftUpLeg"), m.find_bone("RightUpLeg")};
    double closest = 1e9;
    for (Eigen::Index h = 0; h < m.positions.cols(); ++h) {
        if (!hands.contains(dominant[std::size_t(h)])) continue;
        for (Eigen::Index b = 0; b < m.positions.cols(); ++b)
            if (hips_and_thighs.contains(dominant[std::size_t(b)]))
                closest = std::min(closest, double((m.positions.col(h) - m.positions.col(b)).norm()));
    }
    EXPECT_GT(closest, 0.08) << "hands come within " << closest << " m of the hips or thighs";
}

TEST(DefaultAvatar, WalkLastsOverASecondAndLoopsWithoutASeam) {
    const AvatarModel& m = avatar();
    ASSERT_FALSE(m.clips.empty());
    const AvatarClip& walk = m.clips.front();
    EXPECT_EQ(walk.name, "Walk");
    EXPECT_GE(walk.duration_s(), 1.0);
    EXPECT_GE(walk.keys_per_second, 30);
    for (const AvatarClip& clip : m.clips) {
        ASSERT_GE(clip.frame_count(), 2) << clip.name;
        for (std::size_t b = 0; b < m.bones.size(); ++b) {
            EXPECT_EQ(clip.rotations.front()[b].coeffs(), clip.rotations.back()[b].coeffs()) << clip.name << " " << m.bones[b].name;
            EXPECT_EQ(clip.translations.front()[b], clip.translations.back()[b]) << clip.name << " " << m.bones[b].name;
        }
    }
}

// Angle of a bone's rotation about x, degrees, in (-180, 180].
double pitch_deg(const Eigen::Quaterniond& q) {
    const Eigen::Vector3d down = q * Eigen::Vector3d(0, -1, 0);
    return std::atan2(down.z(), -down.y()) * 180.0 / std::numbers::pi;
}

TEST(DefaultAvatar, WalkSwingsLegsAndArmsInOppositionAndBobsThePelvis) {
    const AvatarModel& m = avatar();
    const AvatarClip& walk = m.clips.front();
    const int hips = m.find_bone("Hips"), left_thigh = m.find_bone("LeftUpLeg"), right_thigh = m.find_bone("RightUpLeg"),
              left_knee = m.find_bone("LeftLeg"), left_arm = m.find_bone("LeftArm");
    double knee_min = 1e9, knee_max = -1e9, hip_min = 1e9, hip_max = -1e9, bob_min = 1e9, bob_max = -1e9;
    double arm_leg = 0, legs = 0;
    for (int f = 0; f + 1 < walk.frame_count(); ++f) {
        const auto& r = walk.rotations[std::size_t(f)];
        const double hip = pitch_deg(r[std::size_t(left_thigh)]), knee = -pitch_deg(r[std::size_t(left_knee)]);
        hip_min = std::min(hip_min, hip), hip_max = std::max(hip_max, hip);
        knee_min = std::min(knee_min, knee), knee_max = std::max(knee_max, knee);
        const double y = walk.translations[std::size_t(f)][std::size_t(hips)].y();
        bob_min = std::min(bob_min, y), bob_max = std::max(bob_max, y);
        arm_leg += pitch_deg(r[std::size_t(left_arm)]) * hip;
        legs += hip * pitch_deg(r[std::size_t(right_thigh)]);
    }
    EXPECT_GT(hip_max - hip_min, 25.0);   // Hip flexion/extension.
    EXPECT_GT(knee_max - knee_min, 40.0); // Knee flexes in swing.
    EXPECT_LT(arm_leg, 0.0) << "the left arm swings with the left leg, not against it";
    EXPECT_LT(legs, 0.0) << "the legs swing together, not in turn";
    EXPECT_GT(bob_max - bob_min, 0.01);   // Vertical bob of the pelvis.
    EXPECT_LT(bob_max - bob_min, 0.08);
}

TEST(DefaultAvatar, OptionsOutOfRangeAreRefusedByName) {
    AvatarOptions bad;
    bad.grid_spacing_m = 0;
    const auto r = default_avatar_glb(bad);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("grid_spacing_m"), std::string::npos) << r.error().message;
    bad = {};
    bad.height_m = std::nan("");
    const auto w = write_default_avatar(std::filesystem::temp_directory_path() / "drape_never_written.glb", bad);
    ASSERT_FALSE(w);
    EXPECT_NE(w.error().message.find("height_m"), std::string::npos) << w.error().message;
}

TEST(DefaultAvatar, UnwritablePathIsAnErrorNamingIt) {
    const auto path = std::filesystem::path("/nonexistent-drape-dir/avatar.glb");
    const auto r = write_avatar(avatar(), path);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find(path.string()), std::string::npos) << r.error().message;
}

// The committed file through the importer every character goes through.
TEST(DefaultAvatar, ImportsLikeAnyCharacter) {
    const auto imported = import_character(committed_avatar);
    ASSERT_TRUE(imported) << imported.error().message;
    const CharacterAsset& c = **imported;
    const AvatarModel& m = avatar();
    EXPECT_GE(c.height_m, 1.6f);
    EXPECT_LE(c.height_m, 1.9f);
    EXPECT_GE(c.skeleton->size(), 20u);
    EXPECT_LE(c.skeleton->size(), 30u);
    EXPECT_EQ(c.mesh->vertex_count(), std::size_t(m.positions.cols()));
    EXPECT_EQ(c.mesh->indices.size(), m.indices.size());
    // The file keeps every influence the generator gave: the bones that move vertices are
    // the generator's bones with a positive weight on some vertex (fingerless hands, no
    // twist bones: fewer than the skeleton's bones).
    std::set<int> weighted;
    for (Eigen::Index v = 0; v < m.bone_weights.cols(); ++v)
        for (int k = 0; k < 4; ++k)
            if (m.bone_weights(k, v) > 0) weighted.insert(m.bone_indices(k, v));
    EXPECT_EQ(c.skin_bones, static_cast<int>(weighted.size()));
    EXPECT_LT(c.skin_bones, static_cast<int>(c.skeleton->size()));
    ASSERT_EQ(c.clips.size(), m.clips.size());
    const auto walk = find_clip(c, "Walk");
    ASSERT_TRUE(walk) << walk.error().message;
    const AnimationClip& clip = *c.clips[*walk];
    EXPECT_NEAR(clip.duration_s, m.clips.front().duration_s(), 1e-4);
    EXPECT_FALSE(clip.channels.empty());
    for (const BoneChannel& channel : clip.channels) {
        ASSERT_GE(channel.rotations.size(), 2u);
        EXPECT_TRUE(channel.rotations.front().coeffs().isApprox(channel.rotations.back().coeffs(), 1e-6f))
            << c.skeleton->bone_names[std::size_t(channel.bone)];
    }
    const auto body = fit_character_body(c);
    ASSERT_TRUE(body) << body.error().message;
    EXPECT_EQ(body->hip_bone, c.skeleton->find("Hips"));
}

// The fitted ellipsoids: within a garment's 64 colliders and the fit's budget, one
// ellipsoid per leg bone, a pelvis. With the legs fitted tight (LegFit::tight) they hug
// the body to the target: 99 % of the skin within 1 cm of them and 95 % of their surface
// that stands out of the skin no more than 2 cm out. With the legs' bounding ellipsoids
// (LegFit::bounding) the target is missed between the thighs, and the bound below guards
// the rest of the fit (a trunk or arm piece floating off the body would break it). The
// default (LegFit::automatic) makes the tight fit here: it meets the targets.
constexpr double bounding_fit_p95_bulge_bound_m = 0.08;

void expect_fitted_ellipsoids(const CharacterAsset& c, const std::string& what, LegFit legs) {
    SCOPED_TRACE(what + ", legs " + leg_fit_name(legs));
    FitOptions options;
    options.legs = legs;
    const auto body = fit_character_body(c, options);
    ASSERT_TRUE(body) << body.error().message;
    EXPECT_GE(body->ellipsoids.size(), 12u);
    EXPECT_LE(body->ellipsoids.size(), 64u);
    test::expect_legs(*body, options);
    auto count = [&](BodyRegion r) { return std::count_if(body->ellipsoids.begin(), body->ellipsoids.end(), [&](auto& e) { return e.region == r; }); };
    EXPECT_GE(count(BodyRegion::pelvis), 1);
    EXPECT_TRUE(body->landmarks) << body->landmarks_error;
    const CoverageReport coverage = rest_pose_coverage(c, *body);
    EXPECT_GE(coverage.coverage, 0.99) << "largest gap " << coverage.max_gap_m << " m";
    EXPECT_LE(coverage.p95_bulge_m, legs == LegFit::bounding ? bounding_fit_p95_bulge_bound_m : 0.02)
        << "max bulge " << coverage.max_bulge_m << " m";
    EXPECT_EQ(body->legs, legs == LegFit::automatic ? LegFit::tight : legs);
    // Forearms and hands give by their bulge over the skin at the rest pose, nothing else.
    ASSERT_EQ(coverage.bulge_per_ellipsoid_m.size(), body->ellipsoids.size());
    int giving = 0;
    for (std::size_t i = 0; i < body->ellipsoids.size(); ++i) {
        const EllipsoidShape& e = body->ellipsoids[i];
        const bool arm = e.region == BodyRegion::lower_arm || e.region == BodyRegion::hand;
        EXPECT_NEAR(e.give_m, arm ? coverage.bulge_per_ellipsoid_m[i] : 0.0, 1e-6) << "ellipsoid " << i;
        giving += e.give_m > 0;
    }
    EXPECT_GT(giving, 0);  // some arm piece stands out of its skin (one that does not gives nothing)
}

void expect_hugging_ellipsoids(const CharacterAsset& c, const std::string& what) {
    for (const LegFit legs : {LegFit::automatic, LegFit::tight, LegFit::bounding}) expect_fitted_ellipsoids(c, what, legs);
}

TEST(DefaultAvatar, FittedEllipsoidsHugTheBody) {
    const auto imported = import_character(committed_avatar);
    ASSERT_TRUE(imported) << imported.error().message;
    expect_hugging_ellipsoids(**imported, "default avatar");
}

// Bulge of the fitted ellipsoids over a walk cycle (the skin and the ellipsoids posed
// together): the worst frame's 95th percentile and maximum.
std::pair<double, double> walk_bulge(const CharacterAsset& c, const FitOptions& options) {
    const auto body = fit_character_body(c, options);
    EXPECT_TRUE(body) << body.error().message;
    if (!body) return {1e9, 1e9};
    const auto walk = find_clip(c, "Walk");
    EXPECT_TRUE(walk);
    if (!walk) return {1e9, 1e9};
    const AnimationClip& clip = *c.clips[*walk];
    std::vector<Affine3> local, global, skinning;
    Matrix3X positions, normals;
    double p95 = 0, max = 0;
    constexpr int frames = 8;
    for (int i = 0; i < frames; ++i) {
        sample_clip(clip, *c.skeleton, clip.duration_s * i / frames, true, local);
        compose_pose(*c.skeleton, local, global);
        skinning_matrices(*c.skeleton, global, skinning);
        skin_mesh(*c.mesh, skinning, Affine3::Identity(), positions, normals);
        const CoverageReport r = measure_coverage(body->ellipsoids, global, positions, normals, c.mesh->indices);
        p95 = std::max(p95, r.p95_bulge_m);
        max = std::max(max, r.max_bulge_m);
    }
    return {p95, max};
}

// Hugged legs' ellipsoids stay on the legs as the knees bend: a shin's piece may not grow a
// tip up inside the thigh, hidden there at the rest pose, which would stand out behind
// the bent knee (FitOptions::leg_reach_m). Over 8 frames of the walk the limited fit
// stands out 1.7 cm (95th percentile) and 9.6 cm at most (where a joint bends); with no
// limit, 3.8 cm and 24 cm.
TEST(DefaultAvatar, FittedLegsKeepHuggingThroughTheWalk) {
    const auto imported = import_character(committed_avatar);
    ASSERT_TRUE(imported) << imported.error().message;
    FitOptions options;
    options.legs = LegFit::tight;
    const auto [p95, max] = walk_bulge(**imported, options);
    EXPECT_LE(p95, 0.025);
    EXPECT_LE(max, 0.12);
}

// The leg reach shapes hugged legs only: with the legs' bounding ellipsoids the fit is the
// same whatever the reach, since a reach term on the legs fitted jointly with the trunk
// would still move the trunk's pieces.
TEST(DefaultAvatar, LegReachLeavesTheBoundingFitAlone) {
    const auto imported = import_character(committed_avatar);
    ASSERT_TRUE(imported) << imported.error().message;
    FitOptions reach, none;
    none.leg_reach_m = -1;
    reach.legs = none.legs = LegFit::bounding;
    const auto a = fit_character_body(**imported, reach), b = fit_character_body(**imported, none);
    ASSERT_TRUE(a && b);
    ASSERT_EQ(a->ellipsoids.size(), b->ellipsoids.size());
    for (std::size_t i = 0; i < a->ellipsoids.size(); ++i) {
        EXPECT_EQ(a->ellipsoids[i].bone, b->ellipsoids[i].bone) << i;
        EXPECT_TRUE(a->ellipsoids[i].center.isApprox(b->ellipsoids[i].center, 1e-6f)) << i;
        EXPECT_TRUE(a->ellipsoids[i].radii_m.isApprox(b->ellipsoids[i].radii_m, 1e-6f)) << i;
    }
    // And hugged legs do feel it.
    reach.legs = none.legs = LegFit::tight;
    const auto c = fit_character_body(**imported, reach), d = fit_character_body(**imported, none);
    ASSERT_TRUE(c && d);
    bool differ = c->ellipsoids.size() != d->ellipsoids.size();
    for (std::size_t i = 0; !differ && i < c->ellipsoids.size(); ++i)
        differ = !c->ellipsoids[i].radii_m.isApprox(d->ellipsoids[i].radii_m, 1e-4f);
    EXPECT_TRUE(differ);
}

// With an arm reach (FitOptions::arm_reach_m, an option) an arm's ellipsoids stay on the
// arm: fitted with nothing to hold them, the forearms' tips grow inside the upper arms and
// the hands, hidden at the rest pose (the default avatar's forearm 69 cm long, its skin
// 32 cm), and stand into the armpit and the hip once the arm hangs down. The reach is a
// soft term of the fit, weighed against covering the skin: 2 cm over it allowed.
TEST(DefaultAvatar, ArmEllipsoidsReachNoFurtherThanTheirSkinWithAnArmReach) {
    const auto imported = import_character(committed_avatar);
    ASSERT_TRUE(imported) << imported.error().message;
    const CharacterAsset& c = **imported;
    FitOptions options;
    options.arm_reach_m = 0.05;
    const auto body = fit_character_body(c, options);
    ASSERT_TRUE(body) << body.error().message;
    std::vector<Affine3> global, skinning;
    compose_pose(*c.skeleton, c.skeleton->rest_local, global);
    skinning_matrices(*c.skeleton, global, skinning);
    Matrix3X positions, normals;
    skin_mesh(*c.mesh, skinning, Affine3::Identity(), positions, normals);
    const std::vector<int> dominant = dominant_bones(*c.mesh);
    int arms = 0;
    for (const EllipsoidShape& e : body->ellipsoids) {
        if (e.region != BodyRegion::upper_arm && e.region != BodyRegion::lower_arm) continue;
        ++arms;
        const Affine3 t = ellipsoid_transform(e, global[static_cast<std::size_t>(e.bone)]);
        Eigen::Index k = 0;
        const Real radius = e.radii_m.maxCoeff(&k);
        const Vec3 axis = t.linear().col(k).normalized();
        const Real centre = axis.dot(t.translation());
        Real lo = std::numeric_limits<Real>::max(), hi = -lo;
        for (std::size_t j = 0; j < dominant.size(); ++j)
            if (dominant[j] == e.bone) {
                lo = std::min(lo, axis.dot(positions.col(static_cast<Eigen::Index>(j))));
                hi = std::max(hi, axis.dot(positions.col(static_cast<Eigen::Index>(j))));
            }
        ASSERT_LT(lo, hi) << c.skeleton->bone_names[static_cast<std::size_t>(e.bone)];
        const Real allowed = static_cast<Real>(options.arm_reach_m) + Real(0.02);
        EXPECT_LE(centre + radius, hi + allowed) << c.skeleton->bone_names[static_cast<std::size_t>(e.bone)];
        EXPECT_GE(centre - radius, lo - allowed) << c.skeleton->bone_names[static_cast<std::size_t>(e.bone)];
    }
    EXPECT_EQ(arms, 4);
}

// The avatar reshaped by a map of model space (positions, joints and the clips' bone
// offsets move with it; normals are recomputed), to make builds the generator's options
// (height only) do not give.
template <class Map>
AvatarModel reshaped(AvatarModel m, Map map) {
    for (Eigen::Index v = 0; v < m.positions.cols(); ++v) m.positions.col(v) = map(m.positions.col(v).template cast<double>()).template cast<Real>();
    std::vector<Eigen::Vector3d> old_joints;
    for (AvatarBone& b : m.bones) {
        old_joints.push_back(b.joint_m);
        b.joint_m = map(b.joint_m);
    }
    for (AvatarClip& clip : m.clips)
        for (auto& frame : clip.translations)
            for (std::size_t b = 0; b < m.bones.size(); ++b) {
                const int parent = m.bones[b].parent;
                if (parent < 0) frame[b] += m.bones[b].joint_m - old_joints[b];  // the root keeps its bob and sway
                else frame[b] = m.bones[b].joint_m - m.bones[static_cast<std::size_t>(parent)].joint_m;
            }
    m.normals.setZero(3, m.positions.cols());
    for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
        const auto a = m.indices[t], b = m.indices[t + 1], c = m.indices[t + 2];
        const Vec3 n = (m.positions.col(b) - m.positions.col(a)).cross(m.positions.col(c) - m.positions.col(a));
        for (auto i : {a, b, c}) m.normals.col(i) += n;
    }
    m.normals.colwise().normalize();
    return m;
}

Result<std::shared_ptr<const CharacterAsset>> import_model(const AvatarModel& m, const std::string& name) {
    const auto path = test::binary_dir() / ("avatar_build_" + name + ".glb");
    if (auto ok = write_avatar(m, path); !ok) return std::unexpected(ok.error());
    auto c = import_character(path);
    if (!c) return std::unexpected(c.error());
    return std::shared_ptr<const CharacterAsset>(std::move(*c));
}

// Builds the generator's options (height only) do not give: short, wide, long-legged.
std::vector<std::pair<std::string, AvatarModel>> unusual_builds() {
    const AvatarModel& base = avatar();
    const int hip = base.find_bone("LeftUpLeg");
    EXPECT_GE(hip, 0);
    if (hip < 0) return {};
    const double hip_y = base.bones[std::size_t(hip)].joint_m.y();
    AvatarOptions short_options;
    short_options.height_m = 1.2;
    std::vector<std::pair<std::string, AvatarModel>> builds;
    builds.emplace_back("short", make_default_avatar(short_options));
    builds.emplace_back("wide", reshaped(base, [](const Eigen::Vector3d& p) { return Eigen::Vector3d(1.35 * p.x(), p.y(), 1.25 * p.z()); }));
    // Legs a quarter longer: below the hip joints height stretches, above it shifts up.
    builds.emplace_back("long_legged", reshaped(base, [&](const Eigen::Vector3d& p) {
        return Eigen::Vector3d(p.x(), p.y() < hip_y ? 1.25 * p.y() : p.y() + 0.25 * hip_y, p.z());
    }));
    return builds;
}

// Labelled `figures` (the fits stand at the 2 cm bulge target, where rounding decides): the
// short form fits the first build once and asserts a usable body.
TEST(AvatarBuilds, FittedEllipsoidsHugShortWideAndLongLeggedBodies) {
    auto builds = unusual_builds();
    for (const auto& [name, model] : test::cases(std::span(builds))) {
        const auto c = import_model(model, name);
        ASSERT_TRUE(c) << name << ": " << c.error().message;
        if (test::full_form()) {
            expect_hugging_ellipsoids(**c, name);
            continue;
        }
        const auto body = fit_character_body(**c);
        ASSERT_TRUE(body) << body.error().message;
        ASSERT_FALSE(body->ellipsoids.empty());
        for (const EllipsoidShape& e : body->ellipsoids) EXPECT_TRUE(e.radii_m.allFinite() && e.radii_m.minCoeff() > 0);
    }
}

// Over thin legs, more lines: at the hem, neighbouring layer-1 lines stand at most
// hem_spacing_leg_widths (2) times the thinner leg's width at the hem's height apart. The
// short build's skirt reaches the middle of its shins (7.2 cm thick): 36 lines instead of
// the paper's 27, whose hem lines, 17.7 cm apart, caught round a shin (docs/cloth.md,
// Builders). Without the limit it keeps 27; the default avatar's skirt, its hem over the
// knees, keeps 27 with it. A value the line and particle limits cannot meet is refused with
// the field's name.
TEST(AvatarBuilds, AHemOverThinLegsGetsMoreLines) {
    const auto builds = unusual_builds();
    ASSERT_EQ(builds.at(0).first, "short");
    const auto path = test::binary_dir() / "avatar_build_short.glb";
    ASSERT_TRUE(write_avatar(builds.at(0).second, path));
    const auto lines_of = [](const std::filesystem::path& file, std::optional<double> widths) -> Result<std::uint32_t> {
        SceneDescription scene = sample_scene();
        scene.characters.at(0).file = file;
        if (widths) scene.garments.at(0).parameters.push_back({"hem_spacing_leg_widths", *widths});
        auto world = build_world(scene, {});
        if (!world) return std::unexpected(world.error());
        return world->registry.get<Garment>(world->garments.at(0)).fabric->warp_lines;
    };
    const auto short_lines = lines_of(path, std::nullopt);
    ASSERT_TRUE(short_lines) << short_lines.error().message;
    EXPECT_GT(*short_lines, 27u);
    EXPECT_EQ(*short_lines % 3, 0u);
    const auto unlimited = lines_of(path, 0.0);
    ASSERT_TRUE(unlimited) << unlimited.error().message;
    EXPECT_EQ(*unlimited, 27u);
    const auto default_avatar = lines_of(committed_avatar, std::nullopt);
    ASSERT_TRUE(default_avatar) << default_avatar.error().message;
    EXPECT_EQ(*default_avatar, 27u);
    const auto refused = lines_of(path, 1e-6);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("hem_spacing_leg_widths"), std::string::npos) << refused.error().message;
}

// The skirt and the dress on the wide, the long-legged and the short build, 600 frames of
// their walk, after every frame: the contract asked of characters the team did not tune for
// (strain p99 <= 10 %, max <= 20 %, nothing left inside after the frame beyond 2 mm, pins
// outside). Measured: skirt max 7.4 % (wide), 9.8 % (long-legged) and 10.0 % (short, with
// 36 lines: AHemOverThinLegsGetsMoreLines; 22.9 % with 27), dress 10.0 % on all
// three (on the short build the dress is shortened to clear the ankles).
TEST(AvatarBuilds, SkirtAndDressHoldTheContractOnTheUnusualBuilds) {
    auto builds = unusual_builds();
    for (const auto& [name, model] : test::cases(std::span(builds))) {
        for (const GarmentType type : {GarmentType::skirt, GarmentType::dress}) {
            const std::string garment = type == GarmentType::skirt ? "skirt" : "dress";
            SCOPED_TRACE(name + ", " + garment);
            const auto path = test::binary_dir() / ("avatar_build_" + garment + "_" + name + ".glb");
            ASSERT_TRUE(write_avatar(model, path));
            SceneDescription scene = sample_scene();
            scene.characters.at(0).file = path;
            scene.garments.at(0).type = type;
            auto world = build_world(scene, {});
            ASSERT_TRUE(world) << world.error().message;
            for (int frame = 0; frame < test::frames(600); ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
            const GarmentStats g = run_stats(*world).garments.at(0);
            test::expect_character_contract(g);
            if (test::full_form()) {
                EXPECT_GT(g.penetration_before_response_m, 1e-3) << "the body must have pushed the garment";
            }
        }
    }
}

// Played through the engine's own sampling and skinning: the soles meet the floor all
// through the walk (no floating, no sinking), and the swinging hands keep clear of the
// hips and thighs, where a skirt hangs.
TEST(DefaultAvatar, WalkKeepsTheFeetOnTheFloorAndTheHandsOffTheHips) {
    const auto imported = import_character(committed_avatar);
    ASSERT_TRUE(imported) << imported.error().message;
    const CharacterAsset& c = **imported;
    const auto walk = find_clip(c, "Walk");
    ASSERT_TRUE(walk) << walk.error().message;
    const AnimationClip& clip = *c.clips[*walk];
    const std::vector<int> dominant = dominant_bones(*c.mesh);
    const SkeletonAsset& s = *c.skeleton;
    const std::set<int> hands{s.find("LeftHand"), s.find("RightHand")};
    const std::set<int> hips_and_thighs{s.find("Hips"), s.find("LeftUpLeg"), s.find("RightUpLeg")};
    std::vector<Affine3> local, global, skinning;
    Matrix3X p;
    double lowest_min = 1e9, lowest_max = -1e9, closest = 1e9;
    constexpr int samples = 24;
    for (int i = 0; i < samples; ++i) {
        sample_clip(clip, s, clip.duration_s * i / samples, true, local);
        compose_pose(s, local, global);
        skinning_matrices(s, global, skinning);
        skin_positions(*c.mesh, skinning, Affine3::Identity(), p);
        const double lowest = p.row(1).minCoeff();
        lowest_min = std::min(lowest_min, lowest), lowest_max = std::max(lowest_max, lowest);
        for (Eigen::Index h = 0; h < p.cols(); ++h) {
            if (!hands.contains(dominant[std::size_t(h)])) continue;
            for (Eigen::Index b = 0; b < p.cols(); ++b)
                if (hips_and_thighs.contains(dominant[std::size_t(b)]))
                    closest = std::min(closest, double((p.col(h) - p.col(b)).norm()));
        }
    }
    EXPECT_GT(lowest_min, -0.015) << "a foot sinks into the floor";
    EXPECT_LT(lowest_max, 0.015) << "both feet leave the floor";
    EXPECT_GT(closest, 0.05) << "a hand comes within " << closest << " m of the hips or thighs";
}

}  // namespace
}  // namespace drape
