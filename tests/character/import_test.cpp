// Import normalisation on small characters with known contents (test_character_file.hpp).
#include "drape/engine/assets/character_import.hpp"

#include <algorithm>

#include <gtest/gtest.h>

#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/pose.hpp"
#include "tests/character/test_character_file.hpp"

namespace drape {
namespace {

std::shared_ptr<const CharacterAsset> load(const test::TestCharacter& spec, const ImportOptions& options = {}) {
    const auto dir = test::temp_dir("import");
    write_test_character(spec, dir / "column.gltf");
    auto r = import_character(dir / "column.gltf", options);
    std::filesystem::remove_all(dir);
    EXPECT_TRUE(r) << (r ? "" : r.error().message);
    return r ? *r : nullptr;
}

TEST(CharacterImport, WeightsAreNormalisedToOneWithAtMostFourInfluences) {
    const auto c = load({.weight_sum = 0.8f});
    ASSERT_TRUE(c);
    const MeshAsset& m = *c->mesh;
    ASSERT_EQ(m.vertex_count(), 40u);
    for (Eigen::Index j = 0; j < m.bone_weights.cols(); ++j) {
        EXPECT_NEAR(m.bone_weights.col(j).sum(), 1.0f, 1e-6f) << "vertex " << j;
        EXPECT_GE(m.bone_weights.col(j).minCoeff(), 0.0f);
    }
}

TEST(CharacterImport, ClipTimesAreSecondsNotMilliseconds) {
    const auto c = load({});
    ASSERT_TRUE(c);
    ASSERT_EQ(c->clips.size(), 1u);
    EXPECT_EQ(c->clips[0]->name, "Bend");
    EXPECT_NEAR(c->clips[0]->duration_s, 1.0, 1e-6);
    for (const BoneChannel& ch : c->clips[0]->channels)
        for (float t : ch.rotation_times_s) EXPECT_LE(t, 1.0f + 1e-6f);
}

TEST(CharacterImport, BindPoseSkinsToTheRestMeshExactly) {
    const auto c = load({});
    ASSERT_TRUE(c);
    const SkeletonAsset& s = *c->skeleton;
    std::vector<Affine3> bind_global(s.size()), skinning;
    for (std::size_t i = 0; i < s.size(); ++i) bind_global[i] = s.inverse_bind[i].inverse();
    skinning_matrices(s, bind_global, skinning);
    Matrix3X p, n;
    skin_mesh(*c->mesh, skinning, Affine3::Identity(), p, n);
    ASSERT_EQ(p.cols(), c->mesh->bind_positions.cols());
    Real worst = 0;  // per column: GCC 12 warns falsely on Eigen's AVX-512 max over a dynamic matrix
    for (Eigen::Index j = 0; j < p.cols(); ++j)
        worst = std::max(worst, (p.col(j) - c->mesh->bind_positions.col(j)).cwiseAbs().maxCoeff());
    EXPECT_LE(worst, 1e-6f);
    // And the file's vertices are the bind mesh (glTF is in metres; scale 1).
    const std::vector<float> written = test::test_positions({});
    for (Eigen::Index j = 0; j < p.cols(); ++j)
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(p(k, j), written[std::size_t(3 * j + k)], 1e-5f);
}

TEST(CharacterImport, NodePoseThatDiffersFromTheBindPoseBendsTheRestMesh) {
    // The Child node is bent by 90 degrees in the node pose while the inverse binds
    // describe a straight column: the rest pose must bend the top, not the bind mesh.
    const auto c = load({.child_rest_angle_rad = float(M_PI) / 2});
    ASSERT_TRUE(c);
    std::vector<Affine3> global, skinning;
    compose_pose(*c->skeleton, c->skeleton->rest_local, global);
    skinning_matrices(*c->skeleton, global, skinning);
    Matrix3X p, n;
    skin_positions(*c->mesh, skinning, Affine3::Identity(), p);
    // The top ring (y = 2 at bind) turns about Z around (0, 1, 0) to x = -1, y = 1.
    const Eigen::Index top = 4 * 8;
    EXPECT_NEAR(p(0, top), -1.0f, 1e-4f);
    EXPECT_NEAR(p(1, top), 1.0f + 0.2f, 1e-4f);  // ring vertex 0 sits at x = +0.2 at bind
    EXPECT_LE((c->mesh->bind_positions.col(top) - Vec3(0.2f, 2, 0)).norm(), 1e-5f);
}

TEST(CharacterImport, ScaleOptionAndHeightOptionSetTheUnits) {
    ImportOptions twice;
    twice.scale = 2.0;
    const auto doubled = load({}, twice);
    ASSERT_TRUE(doubled);
    EXPECT_NEAR(doubled->height_m, 4.0f, 1e-4f);
    EXPECT_EQ(doubled->scale_source, ScaleSource::option);
    ImportOptions to_height;
    to_height.height_m = 1.8;
    const auto tall = load({}, to_height);
    ASSERT_TRUE(tall);
    EXPECT_NEAR(tall->height_m, 1.8f, 1e-4f);
    EXPECT_NEAR(tall->scale, 0.9, 1e-5);
    // Root translation keys scale with the character.
    EXPECT_NEAR(tall->clips[0]->travel_m.z(), 0.5f * 0.9f, 1e-5f);
}

TEST(CharacterImport, ImplausibleFileUnitsFallBackToAStandardHeight) {
    ImportOptions options;
    options.max_plausible_height_m = 1.5;
    options.fallback_height_m = 1.75;
    const auto c = load({}, options);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->scale_source, ScaleSource::fallback);
    EXPECT_NEAR(c->height_m, 1.75f, 1e-4f);
}

TEST(CharacterImport, ClipsAreFoundByNameOrIndex) {
    const auto c = load({});
    ASSERT_TRUE(c);
    EXPECT_EQ(find_clip(*c, "Bend").value(), 0u);
    EXPECT_EQ(find_clip(*c, "0").value(), 0u);
    EXPECT_FALSE(find_clip(*c, "1"));
}

TEST(CharacterImport, FbxAxisMetadataBecomesYUp) {
    EXPECT_TRUE(axes_to_drape(1, 1, 2, 1, 0, 1).isIdentity());  // Blender's Y-up export
    // Z up, -Y front (Blender's own axes): file Z -> Y, file -Y -> Z.
    const Mat3 z_up = axes_to_drape(2, 1, 1, -1, 0, 1);
    EXPECT_TRUE((z_up * Vec3(0, 0, 1)).isApprox(Vec3(0, 1, 0)));
    EXPECT_TRUE((z_up * Vec3(0, -1, 0)).isApprox(Vec3(0, 0, 1)));
    EXPECT_NEAR(z_up.determinant(), 1.0f, 1e-6f);
    EXPECT_TRUE(axes_to_drape(1, 1, 1, 1, 0, 1).isIdentity());  // not a permutation
}

TEST(CharacterImport, OptionsAreValidatedWithTheFieldName) {
    ImportOptions bad;
    bad.scale = -1;
    ASSERT_FALSE(validate(bad));
    EXPECT_NE(validate(bad).error().message.find("scale"), std::string::npos);
}

// Bones skinning or fitting cannot use are errors naming the file and the bone; unweighted
// end bones of the same kinds (common in exported rigs) load with a warning.
class BoneCheck : public ::testing::Test {
protected:
    void SetUp() override { m_dir = test::temp_dir("bones"); }
    void TearDown() override { std::filesystem::remove_all(m_dir); }
    Result<std::shared_ptr<const CharacterAsset>> import(const test::TestCharacter& spec) {
        write_test_character(spec, m_dir / "column.gltf");
        return import_character(m_dir / "column.gltf");
    }
    std::string file() const { return (m_dir / "column.gltf").string(); }
    std::filesystem::path m_dir;
};

TEST_F(BoneCheck, ZeroLengthBoneWithSkinnedVerticesIsAnError) {
    // Child's joint moved onto Root's: Root has no direction, and rings 0 to 2 (24 vertices)
    // are skinned to it.
    auto r = import({.child_offset_m = 0});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message, file() + ": bone 'Root' has zero length in the rest pose (its child joints sit at its own "
                                          "joint) but 24 vertices are skinned to it");
}

TEST_F(BoneCheck, ZeroScaleBindMatrixWithSkinnedVerticesIsAnError) {
    auto r = import({.zero_scale_child_bind = true});
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message,
              file() + ": mesh 'Column': bone 'Child' has a singular (zero scale) inverse bind matrix but 24 vertices are skinned to it");
}

TEST_F(BoneCheck, UnweightedZeroLengthEndBoneLoadsWithAWarning) {
    auto r = import({.end_bone_offset_m = 0});
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ((*r)->warnings.size(), 1u);
    EXPECT_EQ((*r)->warnings[0], file() + ": 1 zero-length end bone without skinned vertices, ignored: 'ChildEnd'");
    EXPECT_TRUE((*r)->mesh->bind_positions.allFinite());
    const auto body = fit_character_body(**r);
    ASSERT_TRUE(body) << body.error().message;
    for (const EllipsoidShape& e : body->ellipsoids) EXPECT_TRUE(e.radii_m.allFinite() && e.radii_m.minCoeff() > 0);
}

TEST_F(BoneCheck, UnweightedEndBoneWithAZeroScaleBindLoadsWithAWarning) {
    auto r = import({.end_bone_offset_m = 0.3f, .zero_scale_end_bind = true});
    ASSERT_TRUE(r) << r.error().message;
    ASSERT_EQ((*r)->warnings.size(), 1u);
    EXPECT_EQ((*r)->warnings[0],
              file() + ": mesh 'Column': bone 'ChildEnd' has a singular (zero scale) inverse bind matrix and no skinned vertices, ignored");
    EXPECT_TRUE((*r)->mesh->bind_positions.allFinite());
}

TEST_F(BoneCheck, EndBoneWithALengthGivesNoWarning) {
    auto r = import({.end_bone_offset_m = 0.3f});
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_TRUE((*r)->warnings.empty()) << (*r)->warnings.front();
}

}  // namespace
}  // namespace drape
