// BVH motion applied to a character whose bone names match.
#include <gtest/gtest.h>

#include <fstream>

#include "drape/engine/assets/character_import.hpp"
#include "drape/systems/character/pose.hpp"
#include "tests/character/test_character_file.hpp"

namespace drape {
namespace {

// The column's skeleton in centimetres: Root, Child 100 cm up. Three frames of 0.5 s:
// the root walks 0, 50, 100 cm along Z; the child turns 0, 45, 90 degrees about Z.
const char* bvh_text(const char* child_name) {
    static std::string text;
    text = std::string("HIERARCHY\nROOT Root\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n"
                       "  JOINT ") + child_name + "\n  {\n    OFFSET 0 100 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
                       "    End Site\n    {\n      OFFSET 0 100 0\n    }\n  }\n}\nMOTION\nFrames: 3\nFrame Time: 0.5\n"
                       "0 0 0 0 0 0 0 0 0\n0 0 50 0 0 0 45 0 0\n0 0 100 0 0 0 90 0 0\n";
    return text.c_str();
}

class BvhMotion : public ::testing::Test {
protected:
    void SetUp() override {
        dir = test::temp_dir("bvh");
        test::write_test_character({}, dir / "column.gltf");
        auto r = import_character(dir / "column.gltf");
        ASSERT_TRUE(r) << r.error().message;
        character = *r;
    }
    void TearDown() override { std::filesystem::remove_all(dir); }
    std::filesystem::path dir;
    std::shared_ptr<const CharacterAsset> character;
};

TEST_F(BvhMotion, MatchingJointsDriveTheBonesInMetresAndSeconds) {
    std::ofstream(dir / "walk.bvh") << bvh_text("Child");
    auto clip = import_bvh_motion(dir / "walk.bvh", *character->skeleton);
    ASSERT_TRUE(clip) << clip.error().message;
    EXPECT_EQ((*clip)->name, "walk");
    EXPECT_NEAR((*clip)->duration_s, 1.0, 1e-6);
    EXPECT_NEAR((*clip)->travel_m.z(), 1.0f, 1e-4f);  // 100 cm, rescaled by the bone lengths
    std::vector<Affine3> local, global;
    sample_clip(**clip, *character->skeleton, 1.0, false, local);
    compose_pose(*character->skeleton, local, global);
    const int child = character->skeleton->find("Child");
    const Quat expected(Eigen::AngleAxis<Real>(Real(M_PI / 2), Vec3::UnitZ()));
    EXPECT_TRUE(Quat(local[std::size_t(child)].linear()).isApprox(expected, 1e-4f) ||
                Quat(local[std::size_t(child)].linear()).isApprox(Quat(-expected.coeffs()), 1e-4f));
    // Bone lengths stay the character's: the child is 1 m above the root.
    EXPECT_NEAR((global[std::size_t(child)].translation() - global[std::size_t(child) - 1].translation()).norm(), 1.0f, 1e-4f);
}

TEST_F(BvhMotion, JointNamesThatDoNotMatchAreAClearError) {
    std::ofstream(dir / "other.bvh") << bvh_text("Spine");
    auto clip = import_bvh_motion(dir / "other.bvh", *character->skeleton);
    ASSERT_FALSE(clip);
    EXPECT_NE(clip.error().message.find((dir / "other.bvh").string()), std::string::npos);
    EXPECT_NE(clip.error().message.find("joint(s) not in the character: 'Spine'"), std::string::npos) << clip.error().message;
}

TEST_F(BvhMotion, NotAMotionFile) {
    std::ofstream(dir / "notes.bvh") << "HIERARCHY\nROOT\n";
    auto clip = import_bvh_motion(dir / "notes.bvh", *character->skeleton);
    ASSERT_FALSE(clip);
    EXPECT_NE(clip.error().message.find("notes.bvh: not a readable motion"), std::string::npos) << clip.error().message;
}

}  // namespace
}  // namespace drape
