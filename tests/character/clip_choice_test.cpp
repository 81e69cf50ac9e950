// The clip a character plays when none is named: a walk, else a looping run or other
// locomotion, else an idle, else the first clip; spawning without a clip plays it. A clip
// loops when its ends meet; one that goes somewhere plays once and holds its last pose.
#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <utility>
#include <vector>

#include "drape/components/animation_player.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/engine/assets/character_import.hpp"
#include "drape/systems/character/animation.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/spawn.hpp"
#include "tests/character/test_character_file.hpp"

namespace drape {
namespace {

// A clip on bone 0 whose last rotation key is `turn_rad` from its first (0: it loops).
std::shared_ptr<const AnimationClip> clip(const std::string& name, float turn_rad = 0) {
    auto c = std::make_shared<AnimationClip>();
    c->name = name;
    c->duration_s = 1;
    BoneChannel ch;
    ch.bone = 0;
    ch.rotation_times_s = {0, 0.5f, 1};
    ch.rotations = {Quat::Identity(), Quat(Eigen::AngleAxis<Real>(0.5f, Vec3::UnitY())),
                    Quat(Eigen::AngleAxis<Real>(turn_rad, Vec3::UnitY()))};
    c->channels.push_back(ch);
    return c;
}

CharacterAsset with_clips(std::vector<std::shared_ptr<const AnimationClip>> clips) {
    CharacterAsset c;
    c.source = "test.glb";
    c.clips = std::move(clips);
    return c;
}

std::string chosen(const CharacterAsset& c) {
    const auto choice = choose_default_clip(c);
    return choice ? c.clips[choice->index]->name : "none";
}

TEST(DefaultClip, AWalkWinsWhereverItIs) {
    const CharacterAsset c = with_clips({clip("HumanArmature|Man_Clapping"), clip("HumanArmature|Man_Run"), clip("HumanArmature|Man_Walk")});
    const auto choice = choose_default_clip(c);
    ASSERT_TRUE(choice);
    EXPECT_EQ(choice->index, 2u);
    EXPECT_EQ(choice->reason, "HumanArmature|Man_Walk (name says walk)");
}

TEST(DefaultClip, AWalkNamingNoOtherActionBeatsOneThatDoes) {
    EXPECT_EQ(chosen(with_clips({clip("WalkJump"), clip("Walking")})), "Walking");
    EXPECT_EQ(chosen(with_clips({clip("Walk_Back"), clip("walk-cycle")})), "walk-cycle");
    // Among equals, one that loops, then the first.
    EXPECT_EQ(chosen(with_clips({clip("Walk_A", 1.0f), clip("Walk_B")})), "Walk_B");
    EXPECT_EQ(chosen(with_clips({clip("Walk_A"), clip("Walk_B")})), "Walk_A");
}

TEST(DefaultClip, WithoutAWalkALoopingLocomotionClip) {
    const CharacterAsset c = with_clips({clip("Clapping"), clip("Sprint_Stop", 1.0f), clip("RunningJump"), clip("Run")});
    const auto choice = choose_default_clip(c);
    ASSERT_TRUE(choice);
    EXPECT_EQ(c.clips[choice->index]->name, "Run");
    EXPECT_EQ(choice->reason, "Run (looping locomotion: name says run)");
    // A run that does not loop is no locomotion cycle: the idle wins.
    EXPECT_EQ(chosen(with_clips({clip("Jog", 1.0f), clip("Idle")})), "Idle");
}

// Exports of a cycle often end a few degrees off their first pose: a looping run whose ends
// differ by 6.3 degrees is a run (not passed over for an idle), one whose ends differ by
// 40 degrees goes somewhere else and is not.
TEST(DefaultClip, ARunWhoseEndsNearlyMeetLoops) {
    constexpr float degree = float(M_PI / 180);
    EXPECT_EQ(chosen(with_clips({clip("Idle"), clip("Run", 6.3f * degree)})), "Run");
    EXPECT_EQ(chosen(with_clips({clip("Idle"), clip("Run", 14 * degree)})), "Run");
    EXPECT_EQ(chosen(with_clips({clip("Idle"), clip("Run", 40 * degree)})), "Idle");
    const auto run = with_clips({clip("Idle"), clip("Run", 6.3f * degree)});
    EXPECT_FALSE(choose_default_clip(run)->fell_back);
    EXPECT_TRUE(choose_default_clip(with_clips({clip("Idle"), clip("Wave")}))->fell_back);
    EXPECT_NEAR(loop_mismatch_rad(*clip("Run", 6.3f * degree)), 6.3f * degree, 1e-5f);
}

TEST(DefaultClip, ThenAnIdleThenTheFirstClip) {
    const CharacterAsset idle = with_clips({clip("Wave"), clip("Breathing_Idle")});
    EXPECT_EQ(choose_default_clip(idle)->reason, "Breathing_Idle (no walk or locomotion clip; name says idle)");
    const CharacterAsset none = with_clips({clip("Wave"), clip("Punch")});
    EXPECT_EQ(choose_default_clip(none)->index, 0u);
    EXPECT_EQ(choose_default_clip(none)->reason, "Wave (first clip: no walk, locomotion or idle clip)");
    EXPECT_FALSE(choose_default_clip(with_clips({})));
}

// The test column (test_character_file.hpp) with its clip "Bend" first, then `clips`, and its
// fitted body.
void column_with(std::vector<std::shared_ptr<const AnimationClip>> clips, std::shared_ptr<CharacterAsset>& asset,
                 CharacterBody& body) {
    const auto dir = test::temp_dir("clip_choice");
    test::write_test_character({}, dir / "column.gltf");
    auto imported = import_character(dir / "column.gltf");
    std::filesystem::remove_all(dir);
    ASSERT_TRUE(imported) << imported.error().message;
    asset = std::make_shared<CharacterAsset>(**imported);
    clips.insert(clips.begin(), (*imported)->clips.front());
    asset->clips = std::move(clips);
    auto fitted = fit_character_body(*asset);
    ASSERT_TRUE(fitted) << fitted.error().message;
    body = *fitted;
}

TEST(DefaultClip, SpawnWithoutAClipPlaysTheChoice) {
    std::shared_ptr<CharacterAsset> asset;
    CharacterBody body;
    ASSERT_NO_FATAL_FAILURE(column_with({clip("Walk")}, asset, body));  // "Bend" first, then a walk
    Registry registry;
    auto e = spawn_character(registry, asset, body);
    ASSERT_TRUE(e) << e.error().message;
    ASSERT_TRUE(registry.get<AnimationPlayer>(*e).clip);
    EXPECT_EQ(registry.get<AnimationPlayer>(*e).clip->name, "Walk");
    SpawnOptions named;
    named.clip = "Bend";
    auto f = spawn_character(registry, asset, body, named);
    ASSERT_TRUE(f) << f.error().message;
    EXPECT_EQ(registry.get<AnimationPlayer>(*f).clip->name, "Bend");
}

// A fall or a sit ends far from its first pose: looped, the character would jump back up at
// every wrap and fling its garment. Spawned without saying, it plays once and holds its last
// pose; a clip whose ends meet loops; SpawnOptions::loop overrides either.
TEST(DefaultClip, AClipThatGoesSomewherePlaysOnceAndHoldsItsLastPose) {
    std::shared_ptr<CharacterAsset> asset;
    CharacterBody body;
    ASSERT_NO_FATAL_FAILURE(column_with({clip("Walk"), clip("Fall", 1.5f)}, asset, body));
    Registry registry;
    // Played 1.25 clip lengths from 0.5 s in: the walk wraps to 0.75 s, the fall stops at its end.
    const auto played = [&](const char* name, std::optional<bool> loop) {
        SpawnOptions o;
        o.clip = name;
        o.loop = loop;
        o.start_time_s = 0.5;
        auto e = spawn_character(registry, asset, body, o);
        EXPECT_TRUE(e) << e.error().message;
        auto& player = registry.get<AnimationPlayer>(*e);
        auto& skeleton = registry.get<Skeleton>(*e);
        advance_animation(player, skeleton, nullptr, 1.25);
        return std::pair{player.loop, player.time_s};
    };
    EXPECT_EQ(played("Walk", std::nullopt), std::pair(true, 0.75));
    EXPECT_EQ(played("Fall", std::nullopt), std::pair(false, 1.0));
    EXPECT_EQ(played("Fall", true), std::pair(true, 0.75));
    EXPECT_EQ(played("Walk", false), std::pair(false, 1.0));
}

}  // namespace
}  // namespace drape
