// The whole sample scene (default avatar: animation, skinning, fitted colliders, skirt)
// under the game API: identical inputs give identical bytes across runs and across one
// and two worker threads; a 100 m teleport, a 0.5 s hitch and a 10x time scale keep the
// garment on the body, finite and strain-bounded.
//
// tests/cloth covers determinism on an analytic body and tests/game/scene_test.cpp a 5 m
// teleport judged by the garment's mean; these add the full imported-character pipeline
// and per-particle bounds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "components/ellipsoid_collider.hpp"
#include "components/garment.hpp"
#include "systems/cloth/garment_quality.hpp"
#include "components/transform.hpp"
#include "game/sample_scene.hpp"
#include "game/world.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

SceneDescription sample_with_threads(int threads) {
    SceneDescription s = sample_scene();
    s.solver.threads = threads;
    return s;
}

bool avatar_present() { return fs::exists(sample_scene().characters.at(0).file); }

/// Positions and velocities of every garment, as raw bytes.
std::vector<unsigned char> garment_bytes(World& world) {
    std::vector<unsigned char> bytes;
    for (Entity e : world.garments) {
        const Garment& g = world.registry.get<Garment>(e);
        for (const Matrix3X* m : {&g.state.x, &g.state.v}) {
            const auto* p = reinterpret_cast<const unsigned char*>(m->data());
            bytes.insert(bytes.end(), p, p + sizeof(Real) * static_cast<std::size_t>(m->size()));
        }
    }
    return bytes;
}

/// Runs the sample scene for `frames` frames of 1/60 s; the bytes after the last one.
std::vector<unsigned char> run_sample(int threads, int frames) {
    auto world = build_world(sample_with_threads(threads), {});
    if (!world) {
        ADD_FAILURE() << world.error().message;
        return {};
    }
    for (int f = 0; f < frames; ++f)
        if (auto r = step_world(*world, 1.0 / 60.0); !r) {
            ADD_FAILURE() << r.error().message;
            return {};
        }
    return garment_bytes(*world);
}

/// The garment's anchor ellipsoid centre (the hips for a skirt), world.
Vec3 hip_centre(World& world, const Garment& g) {
    const Entity anchor = g.body.colliders.at(static_cast<std::size_t>(g.body.anchor));
    return world.registry.get<EllipsoidCollider>(anchor).world.translation();
}

/// Largest particle distance from the hip centre.
Real farthest_from_hip(World& world) {
    const Garment& g = world.registry.get<Garment>(world.garments.at(0));
    return (g.state.x.colwise() - hip_centre(world, g)).colwise().norm().maxCoeff();
}

TEST(SampleSceneDeterminism, TwoRunsGiveIdenticalBytes) {
    if (!avatar_present()) GTEST_SKIP() << "the default avatar (assets/avatar.glb) is missing";
    const auto a = run_sample(2, 300);
    const auto b = run_sample(2, 300);
    ASSERT_FALSE(a.empty());
    EXPECT_EQ(a.size(), b.size());
    EXPECT_TRUE(a == b) << "two runs of the sample scene diverged";
}

TEST(SampleSceneDeterminism, OneOrTwoThreadsGiveIdenticalBytes) {
    if (!avatar_present()) GTEST_SKIP() << "the default avatar (assets/avatar.glb) is missing";
    const auto one = run_sample(1, 300);
    const auto two = run_sample(2, 300);
    ASSERT_FALSE(one.empty());
    EXPECT_EQ(one.size(), two.size());
    EXPECT_TRUE(one == two) << "the sample scene differs between one and two worker threads";
}

TEST(SampleSceneDeterminism, BytesChangeWhenTheInputChanges) {
    // Guards the two tests above against comparing something that never moves.
    if (!avatar_present()) GTEST_SKIP() << "the default avatar (assets/avatar.glb) is missing";
    EXPECT_FALSE(run_sample(1, 120) == run_sample(1, 121));
}

TEST(Teleport, HundredMetresResetsEveryParticleAroundTheBodyAtItsNewPlace) {
    if (!avatar_present()) GTEST_SKIP() << "the default avatar (assets/avatar.glb) is missing";
    auto world = build_world(sample_scene(), {});
    ASSERT_TRUE(world) << world.error().message;
    for (int f = 0; f < 60; ++f) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    const Real before = farthest_from_hip(*world);
    EXPECT_LT(before, 1.0f);

    world->registry.get<Transform>(world->characters[0]).position += Vec3(100, 0, 0);
    for (int f = 0; f < 120; ++f) {
        ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        ASSERT_FALSE(has_nonfinite(*world)) << "frame " << f << " after the teleport";
        const Garment& g = world->registry.get<Garment>(world->garments[0]);
        ASSERT_GT(hip_centre(*world, g).x(), 99.0f);
        ASSERT_LT(farthest_from_hip(*world), 1.0f) << "frame " << f << " after the teleport";
    }
    EXPECT_EQ(world->teleports->teleports, 1u);
    EXPECT_GE(world->teleports->resets, 1u);
    EXPECT_EQ(world->registry.get<Garment>(world->garments[0]).counters.non_finite_values, 0u);
}

/// Worst strain the cloth reported (after its strain limit, per fixed step) over `frames` frames of `frame_dt_s` at `time_scale`;
/// checks finite values and that the skirt stays within 1 m of the hips on every frame.
double worst_strain(double frame_dt_s, double time_scale, int frames, double max_frame_dt_s = 0.25) {
    SceneDescription scene = sample_scene();
    scene.solver.time_scale = time_scale;
    scene.solver.max_frame_dt_s = max_frame_dt_s;
    auto world = build_world(scene, {});
    if (!world) {
        ADD_FAILURE() << world.error().message;
        return INFINITY;
    }
    double worst = 0;
    for (int f = 0; f < frames; ++f) {
        auto report = step_world(*world, frame_dt_s);
        if (!report) {
            ADD_FAILURE() << report.error().message;
            return INFINITY;
        }
        EXPECT_FALSE(has_nonfinite(*world)) << "frame " << f;
        EXPECT_LT(farthest_from_hip(*world), 1.0f) << "frame " << f;
        worst = std::max(worst, double(measure_garment(world->registry, world->registry.get<Garment>(world->garments[0])).strain_max));
    }
    EXPECT_EQ(world->teleports->teleports, 0u);
    // The cloth's own count of non-finite values it found (and reset the garment for).
    EXPECT_EQ(world->registry.get<Garment>(world->garments[0]).counters.non_finite_values, 0u);
    return worst;
}

/// Simulated seconds of each run below: the same stretch of the walk for every case.
constexpr double run_s = 6.0;

/// The reference: the sample scene at its own 1/60 s frames.
double normal_strain() { return worst_strain(1.0 / 60.0, 1.0, static_cast<int>(run_s * 60)); }

TEST(Hitch, HalfSecondFramesStayFiniteAndStrainBounded) {
    if (!avatar_present()) GTEST_SKIP() << "the default avatar (assets/avatar.glb) is missing";
    // Every frame a 0.5 s hitch: clamped to max_frame_dt_s (0.5), then capped at
    // max_steps_per_frame (4) fixed steps; 90 such frames simulate 6 s.
    const double hitch = worst_strain(0.5, 1.0, static_cast<int>(run_s * 60 / 4), 0.5);
    const double normal = normal_strain();
    // Strain no worse than a quarter above the normal run's (plus 5 % strain for noise):
    // the long frames must not stretch the cloth beyond what walking does.
    EXPECT_LE(hitch, 1.25 * normal + 0.05) << "normal run: " << normal;
}

TEST(TimeScale, TenTimesFasterStaysFiniteAndStrainBounded) {
    if (!avatar_present()) GTEST_SKIP() << "the default avatar (assets/avatar.glb) is missing";
    // 10x: each 1/60 s frame asks for 10 steps, capped at 4; 90 frames simulate 6 s.
    const double fast = worst_strain(1.0 / 60.0, 10.0, static_cast<int>(run_s * 60 / 4));
    const double normal = normal_strain();
    EXPECT_LE(fast, 1.25 * normal + 0.05) << "normal run: " << normal;
}

}  // namespace
}  // namespace drape
