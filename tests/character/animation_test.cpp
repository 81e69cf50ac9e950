// Sampling, composing and playing clips (method §1.1).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "drape/components/animation_player.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/engine/assets/character_import.hpp"
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

// A run cycle as exports often give it: keys at 30 per second, the child swinging
// 0 -> 40 -> 0 degrees about X but ending 6.3 degrees off where it started, and the root
// travelling 1.2 m forward while bobbing, ending 2 cm lower than it started.
std::shared_ptr<AnimationClip> near_loop_run() {
    auto c = std::make_shared<AnimationClip>();
    c->name = "Run";
    c->duration_s = 0.7;
    BoneChannel child, root;
    child.bone = 1;
    root.bone = 0;
    constexpr int keys = 22;  // 0 .. 0.7 s
    constexpr double degree = M_PI / 180;
    for (int k = 0; k < keys; ++k) {
        const double u = double(k) / (keys - 1);
        const double angle = 40 * degree * std::sin(M_PI * u) + 6.3 * degree * u;
        child.rotation_times_s.push_back(float(c->duration_s * u));
        child.rotations.emplace_back(Eigen::AngleAxis<Real>(Real(angle), Vec3::UnitX()));
        root.position_times_s.push_back(float(c->duration_s * u));
        root.positions.emplace_back(0, Real(0.05 * std::sin(2 * M_PI * u) - 0.02 * u), Real(1.2 * u));
    }
    c->channels = {child, root};
    return c;
}

// Played as a loop, a near-loop's seam is blended: the pose at the clip's end is its
// first pose, the poses just before the end step no further than the keys do elsewhere,
// the travel stays the cycle's, and the first part of the clip is untouched. Played
// once, it is sampled as the file gives it.
TEST(ClipSampling, ANearLoopLoopsWithItsSeamBlended) {
    auto s = chain();
    auto clip = near_loop_run();
    compute_clip_travel(*clip, *s);
    blend_loop_seam(*clip);
    ASSERT_GT(clip->seam_blend_s, 0);
    ASSERT_LE(clip->seam_blend_s, 0.2);
    EXPECT_NEAR(clip->travel_m.z(), 1.2f, 1e-5f);
    std::vector<Affine3> local, start;
    sample_clip(*clip, *s, 0, true, start, true);
    sample_clip(*clip, *s, clip->duration_s, true, local, true);
    EXPECT_LT(Quat(local[1].linear()).angularDistance(Quat(start[1].linear())), 1e-4f);
    EXPECT_LT((local[0].translation() - start[0].translation()).norm(), 1e-5f);
    // Without the seam the end is 6.3 degrees and 2 cm off.
    sample_clip(*clip, *s, clip->duration_s, true, local, false);
    EXPECT_GT(Quat(local[1].linear()).angularDistance(Quat(start[1].linear())), 0.1f);
    EXPECT_GT((local[0].translation() - start[0].translation()).norm(), 0.019f);
    // Across the wrap and through the blend, no step is larger than the largest step
    // elsewhere plus the blend's own steepest share of the 6.3 degrees (smoothstep: 1.5 x
    // the mean rate over the blend), in 1/120 s steps.
    auto pose_at = [&](double t) {
        std::vector<Affine3> p;
        sample_clip(*clip, *s, t, true, p, true);
        return p;
    };
    auto step = [&](double a, double b) {
        const auto pa = pose_at(a), pb = pose_at(b);
        return Quat(pa[1].linear()).angularDistance(Quat(pb[1].linear()));
    };
    Real worst_before = 0, worst_seam = 0;
    const double dt = 1.0 / 120;
    for (double t = 0; t + dt < clip->duration_s - clip->seam_blend_s; t += dt) worst_before = std::max(worst_before, step(t, t + dt));
    for (double t = clip->duration_s - clip->seam_blend_s; t + dt <= clip->duration_s + 1e-9; t += dt)
        worst_seam = std::max(worst_seam, step(t, t + dt));
    worst_seam = std::max(worst_seam, step(clip->duration_s, 0));  // the wrap itself
    const Real gap = Real(6.3 * M_PI / 180);
    EXPECT_LE(worst_seam, worst_before + Real(1.5 * dt / clip->seam_blend_s) * gap + 1e-5f);
    EXPECT_LT(step(clip->duration_s, 0), 1e-4f);
    // Before the blend: the file's pose.
    const double early = 0.3;
    std::vector<Affine3> blended, as_given;
    sample_clip(*clip, *s, early, true, blended, true);
    sample_clip(*clip, *s, early, true, as_given, false);
    EXPECT_TRUE(blended[1].isApprox(as_given[1], 1e-6f));
    EXPECT_TRUE(blended[0].isApprox(as_given[0], 1e-6f));
}

// A clip that goes somewhere (ends 40 degrees off) gets no seam; one whose ends meet needs none.
TEST(ClipSampling, OnlyANearLoopGetsASeam) {
    auto s = chain();
    auto far = bend_and_walk();  // the child ends 90 degrees off
    compute_clip_travel(*far, *s);
    blend_loop_seam(*far);
    EXPECT_EQ(far->seam_blend_s, 0);
    auto closed = near_loop_run();
    closed->channels[0].rotations.back() = closed->channels[0].rotations.front();
    closed->channels[1].positions.back() = closed->channels[1].positions.front() + Vec3(0, 0, 1.2f);
    compute_clip_travel(*closed, *s);
    blend_loop_seam(*closed);
    EXPECT_EQ(closed->seam_blend_s, 0);
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
