// The whole sample scene (default avatar: animation, skinning, fitted colliders, skirt)
// under the game API: identical inputs give identical bytes across runs and across one
// and two worker threads; a 100 m teleport keeps the garment on the body; a 0.5 s hitch and
// a 10x time scale keep it finite, without a reset, and within the quality contract after
// every frame.
//
// tests/cloth covers determinism on an analytic body and tests/game/world_test.cpp a 5 m
// teleport judged by the garment's mean; these add the full imported-character pipeline
// and per-particle bounds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/systems/cloth/garment_quality.hpp"
#include "drape/components/transform.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/world.hpp"
#include "tests/figures.hpp"

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
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
    const auto a = run_sample(2, 300);
    const auto b = run_sample(2, 300);
    ASSERT_FALSE(a.empty());
    EXPECT_EQ(a.size(), b.size());
    EXPECT_TRUE(a == b) << "two runs of the sample scene diverged";
}

TEST(SampleSceneDeterminism, OneOrTwoThreadsGiveIdenticalBytes) {
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
    const auto one = run_sample(1, 300);
    const auto two = run_sample(2, 300);
    ASSERT_FALSE(one.empty());
    EXPECT_EQ(one.size(), two.size());
    EXPECT_TRUE(one == two) << "the sample scene differs between one and two worker threads";
}

TEST(SampleSceneDeterminism, BytesChangeWhenTheInputChanges) {
    // Guards the two tests above against comparing something that never moves.
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
    EXPECT_FALSE(run_sample(1, 120) == run_sample(1, 121));
}

TEST(Teleport, HundredMetresResetsEveryParticleAroundTheBodyAtItsNewPlace) {
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
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

/// What a run shows after its frames: the garment measured after every whole frame.
struct AfterFrames {
    double strain_max = 0;       ///< Largest structural strain after any frame.
    double strain_p99 = 0;       ///< 99th percentile over every spring of every frame.
    double penetration_m = 0;    ///< Deepest free particle inside an ellipsoid after any frame.
};

/// Runs the sample scene for `frames` frames of `frame_dt_s` at `time_scale`, measuring the
/// skirt after every frame (systems/cloth/garment_quality.hpp); checks finite values, no
/// reset, and that the skirt stays within 1 m of the hips on every frame.
AfterFrames after_frames(double frame_dt_s, double time_scale, int full_frames, double max_frame_dt_s = 0.25) {
    const int frames = test::frames(full_frames);
    SceneDescription scene = sample_scene();
    scene.solver.time_scale = time_scale;
    scene.solver.max_frame_dt_s = max_frame_dt_s;
    auto world = build_world(scene, {});
    if (!world) {
        ADD_FAILURE() << world.error().message;
        return {INFINITY, INFINITY, INFINITY};
    }
    AfterFrames out;
    StrainHistogram strains;
    for (int f = 0; f < frames; ++f) {
        auto report = step_world(*world, frame_dt_s);
        if (!report) {
            ADD_FAILURE() << report.error().message;
            return {INFINITY, INFINITY, INFINITY};
        }
        EXPECT_FALSE(has_nonfinite(*world)) << "frame " << f;
        EXPECT_LT(farthest_from_hip(*world), 1.0f) << "frame " << f;
        const GarmentQuality q = measure_garment(world->registry, world->registry.get<Garment>(world->garments[0]), &strains);
        out.strain_max = std::max(out.strain_max, double(q.strain_max));
        out.penetration_m = std::max(out.penetration_m, double(q.penetration_m));
    }
    out.strain_p99 = strains.percentile(0.99);
    EXPECT_EQ(world->teleports->teleports, 0u);
    // The cloth resets a garment that went non-finite, so finite positions alone prove
    // nothing: its own counts of non-finite values and resets must stay zero.
    const Garment& g = world->registry.get<Garment>(world->garments[0]);
    EXPECT_EQ(g.counters.non_finite_values, 0u);
    EXPECT_EQ(g.counters.resets, 0u);
    return out;
}

/// Simulated seconds of each run below: the same stretch of the walk for every case.
constexpr double run_s = 6.0;

/// The reference: the sample scene at its own 1/60 s frames.
AfterFrames normal_run() { return after_frames(1.0 / 60.0, 1.0, static_cast<int>(run_s * 60)); }

/// The quality contract after every frame (docs/cloth.md): structural strain p99 <= 10 %,
/// max <= 15 %, no free particle more than 0.5 mm inside an ellipsoid; and no worse than a
/// quarter above the normal run's strain (plus 5 % strain for noise). With the clamp and the
/// cap working, the long frames below simulate the normal run's fixed steps, four per frame,
/// so the comparison fails only when they do not (one long step, or the steps not capped).
void expect_contract(const AfterFrames& run, const AfterFrames& normal) {
    if (test::short_form()) return;  // labelled `figures`: the short form runs clean (after_frames)
    EXPECT_LE(run.strain_p99, 0.10);
    EXPECT_LE(run.strain_max, 0.15);
    EXPECT_LE(run.penetration_m, 0.5e-3);
    EXPECT_LE(run.strain_max, 1.25 * normal.strain_max + 0.05) << "normal run: " << normal.strain_max;
    ::testing::Test::RecordProperty("strain_max", std::to_string(run.strain_max));
    ::testing::Test::RecordProperty("strain_p99", std::to_string(run.strain_p99));
    ::testing::Test::RecordProperty("penetration_m", std::to_string(run.penetration_m));
}

// Catches long frames that reach the cloth as one long step (the clamp or the cap lost, or
// the substep rule not following the step) and stretch or fling the skirt.
TEST(Hitch, HalfSecondFramesStayFiniteAndWithinTheContract) {
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
    // Every frame a 0.5 s hitch: clamped to max_frame_dt_s (0.5), then capped at
    // max_steps_per_frame (4) fixed steps; 90 such frames simulate 6 s.
    const AfterFrames hitch = after_frames(0.5, 1.0, static_cast<int>(run_s * 60 / 4), 0.5);
    expect_contract(hitch, normal_run());
}

// Catches a time scale that lengthens the fixed step instead of taking more of them.
TEST(TimeScale, TenTimesFasterStaysFiniteAndWithinTheContract) {
    ASSERT_TRUE(avatar_present()) << "the default avatar (assets/avatar.glb) is part of the project";
    // 10x: each 1/60 s frame asks for 10 steps, capped at 4; 90 frames simulate 6 s.
    const AfterFrames fast = after_frames(1.0 / 60.0, 10.0, static_cast<int>(run_s * 60 / 4));
    expect_contract(fast, normal_run());
}

}  // namespace
}  // namespace drape
