// BVH motion retargeted by humanoid part (import_bvh_motion; docs/characters.md, "Motion
// from a BVH file"): names of the common rigs, a motion in another rig's names driving the
// default avatar as its own clip does, and driving a shared character with other rest poses.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <map>
#include <string>
#include <vector>

#include "drape/engine/assets/character_import.hpp"
#include "drape/engine/assets/skinning.hpp"
#include "drape/systems/character/bvh_export.hpp"
#include "drape/systems/character/pose.hpp"
#include "tests/shared_assets.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

TEST(HumanoidPart, ReadsTheCommonNamingSchemes) {
    const std::vector<std::pair<const char*, const char*>> cases = {
        {"Hips", "hips"}, {"mixamorig:Hips", "hips"}, {"pelvis", "hips"},
        {"Spine1", "spine"}, {"Abdomen", "spine"}, {"Torso", "spine"}, {"LowerBack", "spine"}, {"Chest", "spine"},
        {"Neck", "neck"}, {"Neck1", "neck"}, {"Head", "head"}, {"HeadTop_End", ""},
        {"LeftUpLeg", "upper_leg.l"}, {"mixamorig:RightUpLeg", "upper_leg.r"}, {"UpperLeg.L", "upper_leg.l"},
        {"UpperLegR", "upper_leg.r"}, {"thigh_l", "upper_leg.l"}, {"L_Thigh", "upper_leg.l"},
        {"LeftLeg", "lower_leg.l"}, {"LowerLeg.R", "lower_leg.r"}, {"calf_r", "lower_leg.r"}, {"shin.L", "lower_leg.l"},
        {"LeftFoot", "foot.l"}, {"Foot.R", "foot.r"}, {"LeftToeBase", "toe.l"}, {"Toes.L", "toe.l"},
        {"LeftShoulder", "shoulder.l"}, {"clavicle_r", "shoulder.r"}, {"ShoulderL", "shoulder.l"},
        {"LeftArm", "upper_arm.l"}, {"UpperArm.R", "upper_arm.r"}, {"LeftForeArm", "lower_arm.l"}, {"LowerArmL", "lower_arm.l"},
        {"LeftHand", "hand.l"}, {"Fist.R", "hand.r"}, {"hand_r", "hand.r"},
        {"LHipJoint", ""}, {"LeftHandIndex1", ""}, {"LThumb", ""}, {"Armature", ""}, {"Root", ""}, {"LeftToe_End", ""}};
    for (const auto& [name, part] : cases) EXPECT_EQ(humanoid_part(name), part) << name;
}

class Retarget : public ::testing::Test {
protected:
    void SetUp() override {
        dir = fs::temp_directory_path() / ("drape_bvh_retarget_" + std::to_string(::getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir);
        auto avatar = import_character(test::source_dir() / "assets" / "avatar.glb");
        ASSERT_TRUE(avatar) << avatar.error().message;
        this->avatar = *avatar;
        auto walk = find_clip(*this->avatar, "Walk");
        ASSERT_TRUE(walk) << walk.error().message;
        this->walk = this->avatar->clips[*walk];
    }
    void TearDown() override { fs::remove_all(dir); }

    // Model-space joint positions of `clip` on `skeleton` at `t` (not in place).
    static std::vector<Vec3> joints_at(const AnimationClip& clip, const SkeletonAsset& skeleton, double t) {
        std::vector<Affine3> local, global;
        sample_clip(clip, skeleton, t, false, local);
        compose_pose(skeleton, local, global);
        std::vector<Vec3> out;
        for (const Affine3& g : global) out.push_back(g.translation());
        return out;
    }

    fs::path dir;
    std::shared_ptr<const CharacterAsset> avatar;
    std::shared_ptr<const AnimationClip> walk;
};

// The default avatar's walk written in Quaternius' names (the shared characters' rig) and
// read back onto the avatar: every joint where its own clip puts it, within a millimetre
// (the file holds 7 digits; the clip is sampled at 60 frames per second, the check between
// two frames too).
TEST_F(Retarget, AWalkInAnotherRigsNamesDrivesTheAvatarAsItsOwnClip) {
    const std::map<std::string, std::string, std::less<>> names = {
        {"Spine", "Abdomen"}, {"Spine1", "Torso"}, {"Spine2", "Chest"}, {"LeftShoulder", "Shoulder.L"},
        {"LeftArm", "UpperArm.L"}, {"LeftForeArm", "LowerArm.L"}, {"LeftHand", "Fist.L"}, {"RightShoulder", "Shoulder.R"},
        {"RightArm", "UpperArm.R"}, {"RightForeArm", "LowerArm.R"}, {"RightHand", "Fist.R"}, {"LeftUpLeg", "UpperLeg.L"},
        {"LeftLeg", "LowerLeg.L"}, {"LeftFoot", "Foot.L"}, {"LeftToeBase", "Toes.L"}, {"RightUpLeg", "UpperLeg.R"},
        {"RightLeg", "LowerLeg.R"}, {"RightFoot", "Foot.R"}, {"RightToeBase", "Toes.R"}};
    const auto rename = [&](std::string_view bone) {
        const auto it = names.find(bone);
        return it == names.end() ? std::string(bone) : it->second;
    };
    const fs::path file = dir / "walk_quaternius.bvh";
    ASSERT_TRUE(write_bvh_motion(file, *walk, *avatar->skeleton, 60, rename));
    EXPECT_FALSE(write_bvh_motion(file, *walk, *avatar->skeleton, 60, rename)) << "never overwrites";
    std::vector<std::string> notes;
    auto clip = import_bvh_motion(file, *avatar->skeleton, {}, &notes);
    ASSERT_TRUE(clip) << clip.error().message;
    EXPECT_NEAR((*clip)->duration_s, walk->duration_s, 1.0 / 60);
    double worst = 0;
    for (double t : {0.0, 0.25, 0.5 + 1.0 / 120, 0.8}) {
        const auto expected = joints_at(*walk, *avatar->skeleton, t), got = joints_at(**clip, *avatar->skeleton, t);
        for (std::size_t b = 0; b < expected.size(); ++b) worst = std::max(worst, double((expected[b] - got[b]).norm()));
    }
    EXPECT_LT(worst, 0.01) << "largest joint distance from the avatar's own clip, m";
    RecordProperty("worst_joint_mm", std::to_string(1000 * worst));
}

// The same walk, in the avatar's own (Mixamo) names, on Male_Casual: another naming, other
// rest rotations, other proportions. His legs alternate as the avatar's do (the left foot
// ahead, then behind, by more than 15 cm), his pelvis stays at his own height, and the
// bones the clip only turns keep their lengths.
TEST_F(Retarget, TheAvatarsWalkDrivesASharedCharacter) {
    const fs::path male = test::shared_assets() / "characters/male_casual/Male_Casual.fbx";
    DRAPE_REQUIRE_SHARED(male);
    auto character = import_character(male);
    ASSERT_TRUE(character) << character.error().message;
    const SkeletonAsset& skeleton = *(*character)->skeleton;
    const fs::path file = dir / "walk.bvh";
    ASSERT_TRUE(write_bvh_motion(file, *walk, *avatar->skeleton, 60));
    std::vector<std::string> notes;
    auto clip = import_bvh_motion(file, skeleton, {}, &notes);
    ASSERT_TRUE(clip) << clip.error().message;
    // His rig (Quaternius'): the legs hang from "Body", the pelvis, the spine from "Hips"
    // beside them; "Foot.L" and "Foot.R" are IK bones under the root, which the motion
    // places where the shins end.
    const int left_foot = skeleton.find("Foot.L"), right_foot = skeleton.find("Foot.R"), hips = skeleton.find("Body");
    std::vector<bool> moved(skeleton.size(), false);  // bones the clip places (the pelvis, the IK feet)
    for (const BoneChannel& ch : (*clip)->channels)
        if (!ch.positions.empty()) moved[std::size_t(ch.bone)] = true;
    EXPECT_TRUE(moved[std::size_t(hips)]);
    EXPECT_TRUE(moved[std::size_t(left_foot)]);
    ASSERT_GE(left_foot, 0);
    ASSERT_GE(hips, 0);
    const auto rest = joints_at(AnimationClip{}, skeleton, 0);
    const auto avatar_rest = joints_at(AnimationClip{}, *avatar->skeleton, 0);
    const int a_left = avatar->skeleton->find("LeftFoot"), a_right = avatar->skeleton->find("RightFoot");
    double lead_min = 1e9, lead_max = -1e9, avatar_min = 1e9, avatar_max = -1e9;
    for (double t = 0; t < walk->duration_s; t += 1.0 / 30) {
        const auto pose = joints_at(**clip, skeleton, t), avatar_pose = joints_at(*walk, *avatar->skeleton, t);
        const double lead = pose[std::size_t(left_foot)].z() - pose[std::size_t(right_foot)].z();
        const double avatar_lead = avatar_pose[std::size_t(a_left)].z() - avatar_pose[std::size_t(a_right)].z();
        lead_min = std::min(lead_min, lead);
        lead_max = std::max(lead_max, lead);
        avatar_min = std::min(avatar_min, avatar_lead);
        avatar_max = std::max(avatar_max, avatar_lead);
        // The hips within 10 % of his rest height.
        EXPECT_NEAR(pose[std::size_t(hips)].y(), rest[std::size_t(hips)].y(), 0.1 * rest[std::size_t(hips)].y()) << "t = " << t;
        for (std::size_t b = 0; b < skeleton.size(); ++b) {
            const int p = skeleton.parents[b];
            if (p < 0 || moved[b]) continue;
            EXPECT_NEAR((pose[b] - pose[std::size_t(p)]).norm(), (rest[b] - rest[std::size_t(p)]).norm(), 1e-3) << skeleton.bone_names[b];
        }
    }
    EXPECT_LT(lead_min, -0.15);
    EXPECT_GT(lead_max, 0.15);
    // He strides in proportion to the avatar (facing the same way: the same sign).
    EXPECT_GT(lead_max * avatar_max, 0);
    EXPECT_NEAR(lead_max - lead_min, avatar_max - avatar_min, 0.5 * (avatar_max - avatar_min));
    (void)avatar_rest;
}

// A motion without hips or legs the character has: one error naming the file, what is
// missing and the joints there are.
TEST_F(Retarget, AMotionWithoutLegsIsAClearError) {
    const fs::path file = dir / "arm.bvh";
    std::ofstream(file) << "HIERARCHY\nROOT Shoulder\n{\n  OFFSET 0 1.4 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
                           "Yrotation\n  JOINT Elbow\n  {\n    OFFSET 0.3 0 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    End Site\n"
                           "    {\n      OFFSET 0.3 0 0\n    }\n  }\n}\nMOTION\nFrames: 2\nFrame Time: 0.5\n0 1.4 0 0 0 0 0 0 0\n"
                           "0 1.4 0 0 0 0 45 0 0\n";
    auto clip = import_bvh_motion(file, *avatar->skeleton);
    ASSERT_FALSE(clip);
    const std::string& message = clip.error().message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find("upper_leg.l"), std::string::npos) << message;
    EXPECT_NE(message.find("Elbow"), std::string::npos) << message;
}

}  // namespace
}  // namespace drape
