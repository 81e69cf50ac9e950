// Sampling, composing and playing clips (method §1.1).
#include <gtest/gtest.h>

#include <cmath>

#include "drape/components/animation_player.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/systems/character/animation.hpp"
#include "drape/systems/character/pose.hpp"

namespace drape {
namespace {

// Two bones: root at the origin, child one metre up.
std::shared_ptr<SkeletonAsset> chain() {
    auto s = std::make_shared<SkeletonAsset>();
    s->bone_names = {"root", "child"};
    s->parents = {-1, 0};
    s->rest_translation = {Vec3::Zero(), Vec3(0, 1, 0)};
    s->rest_rotation = {Quat::Identity(), Quat::Identity()};
    s->rest_scale = {Vec3::Ones(), Vec3::Ones()};
    for (int i = 0; i < 2; ++i) s->rest_local.push_back(compose_trs(s->rest_translation[i], s->rest_rotation[i], s->rest_scale[i]));
    std::vector<Affine3> g;
    compose_pose(*s, s->rest_local, g);
    for (auto& m : g) s->inverse_bind.push_back(m.inverse());
    return s;
}

// Child turns 0 -> 90 degrees about Z over 1 s; the root walks 2 m along +Z.
std::shared_ptr<AnimationClip> bend_and_walk() {
    auto c = std::make_shared<AnimationClip>();
    c->name = "walk";
    c->duration_s = 1;
    BoneChannel child;
    child.bone = 1;
    child.rotation_times_s = {0, 0.5f, 1};
    child.rotations = {Quat::Identity(), Quat(Eigen::AngleAxis<Real>(Real(M_PI / 4), Vec3::UnitZ())),
                       Quat(Eigen::AngleAxis<Real>(Real(M_PI / 2), Vec3::UnitZ()))};
    BoneChannel root;
    root.bone = 0;
    root.position_times_s = {0, 1};
    root.positions = {Vec3(0, 0, 0), Vec3(0, 0, 2)};
    c->channels = {child, root};
    return c;
}

TEST(ClipSampling, SamplingAtAKeyReturnsTheKey) {
    auto s = chain();
    auto clip = bend_and_walk();
    std::vector<Affine3> local;
    for (std::size_t k = 0; k < 3; ++k) {
        sample_clip(*clip, *s, clip->channels[0].rotation_times_s[k], false, local);
        EXPECT_TRUE(Quat(local[1].linear()).isApprox(clip->channels[0].rotations[k], 1e-6f)) << "key " << k;
        EXPECT_TRUE(local[1].translation().isApprox(Vec3(0, 1, 0)));  // not animated: rest
    }
    sample_clip(*clip, *s, 1.0, false, local);
    EXPECT_TRUE(local[0].translation().isApprox(Vec3(0, 0, 2)));
}

TEST(ClipSampling, BetweenKeysTranslationLerpsAndRotationSlerps) {
    auto s = chain();
    auto clip = bend_and_walk();
    std::vector<Affine3> local;
    sample_clip(*clip, *s, 0.25, false, local);
    EXPECT_TRUE(local[0].translation().isApprox(Vec3(0, 0, 0.5f), 1e-6f));
    const Quat expected(Eigen::AngleAxis<Real>(Real(M_PI / 8), Vec3::UnitZ()));
    EXPECT_TRUE(Quat(local[1].linear()).isApprox(expected, 1e-5f));
}

TEST(ClipSampling, TimeOutsideTheKeysHoldsTheEndKeys) {
    auto s = chain();
    auto clip = bend_and_walk();
    std::vector<Affine3> local;
    sample_clip(*clip, *s, -3, false, local);
    EXPECT_TRUE(local[0].translation().isZero());
    sample_clip(*clip, *s, 7, false, local);
    EXPECT_TRUE(local[0].translation().isApprox(Vec3(0, 0, 2)));
}

TEST(ClipSampling, TimeThatRoundsUpToTheLastKeyInFloatHoldsTheLastKey) {
    auto s = chain();
    auto clip = bend_and_walk();
    std::vector<Affine3> local;
    sample_clip(*clip, *s, std::nextafter(1.0, 0.0), false, local);  // rounds to 1.0f
    EXPECT_TRUE(local[0].translation().isApprox(Vec3(0, 0, 2)));
    sample_clip(*clip, *s, std::nan(""), false, local);
    EXPECT_TRUE(local[0].matrix().allFinite());
}

TEST(ClipSampling, InPlaceRemovesTheTravelButKeepsTheRest) {
    auto s = chain();
    auto clip = bend_and_walk();
    clip->motion_bone = 0;
    clip->travel_m = clip->travel_local = Vec3(0, 0, 2);
    std::vector<Affine3> local;
    for (double t : {0.0, 0.3, 0.7, 1.0}) {
        sample_clip(*clip, *s, t, true, local);
        EXPECT_NEAR(local[0].translation().z(), 0.0f, 1e-6f) << t;
    }
}

TEST(PoseComposition, GlobalIsTheProductDownTheHierarchy) {
    auto s = chain();
    std::vector<Affine3> local = s->rest_local, global;
    local[0] = compose_trs(Vec3(1, 0, 0), Quat(Eigen::AngleAxis<Real>(Real(M_PI / 2), Vec3::UnitZ())), Vec3::Ones());
    compose_pose(*s, local, global);
    // The child sits one metre along the root's rotated Y: (1,0,0) + (-1,0,0).
    EXPECT_LE(global[1].translation().norm(), 1e-6f);
    EXPECT_TRUE(global[1].linear().isApprox(local[0].linear()));
}

TEST(ClipTime, LoopingWrapsAndCountsCyclesClampingDoesNot) {
    ClipTime t = wrap_clip_time(2.25, 1.0, true);
    EXPECT_NEAR(t.time_s, 0.25, 1e-12);
    EXPECT_EQ(t.cycles, 2);
    t = wrap_clip_time(-0.25, 1.0, true);
    EXPECT_NEAR(t.time_s, 0.75, 1e-12);
    EXPECT_EQ(t.cycles, -1);
    t = wrap_clip_time(2.25, 1.0, false);
    EXPECT_EQ(t.time_s, 1.0);
    EXPECT_EQ(t.cycles, 0);
    EXPECT_EQ(wrap_clip_time(std::nan(""), 1.0, true).time_s, 0.0);
}

TEST(AnimationPlayback, RootMotionCarriesTheTransformWhenTheClipLoops) {
    auto s = chain();
    auto clip = bend_and_walk();
    clip->motion_bone = 0;
    clip->travel_m = clip->travel_local = Vec3(0, 0, 2);
    AnimationPlayer player;
    player.clip = clip;
    player.in_place = false;
    Skeleton skeleton;
    skeleton.asset = s;
    Transform transform;
    transform.rotation = Quat(Eigen::AngleAxis<Real>(Real(M_PI / 2), Vec3::UnitY()));  // facing +X
    // 2.5 s in 0.1 s steps: two loops, then half a cycle.
    Vec3 last_world = Vec3::Zero();
    for (int i = 0; i < 25; ++i) {
        advance_animation(player, skeleton, &transform, 0.1);
        const Vec3 world = transform.matrix() * skeleton.global[0].translation();
        if (i > 0) {
            EXPECT_NEAR((world - last_world).norm(), 0.2f, 1e-4f) << "step " << i;  // no jump at the wrap
        }
        last_world = world;
    }
    EXPECT_EQ(player.cycles, 2);
    EXPECT_TRUE(transform.position.isApprox(Vec3(4, 0, 0), 1e-4f)) << transform.position.transpose();
    EXPECT_TRUE(last_world.isApprox(Vec3(5, 0, 0), 1e-4f)) << last_world.transpose();
}

TEST(AnimationPlayback, SkinningMatricesFollowThePose) {
    auto s = chain();
    AnimationPlayer player;
    player.clip = bend_and_walk();
    Skeleton skeleton;
    skeleton.asset = s;
    advance_animation(player, skeleton, nullptr, 0.5);
    ASSERT_EQ(skeleton.skinning.size(), 2u);
    for (int i = 0; i < 2; ++i)
        EXPECT_TRUE(skeleton.skinning[i].isApprox(skeleton.global[i] * s->inverse_bind[i]));
}

}  // namespace
}  // namespace drape
