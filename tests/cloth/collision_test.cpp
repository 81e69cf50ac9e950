// Ellipsoid collision (method §5): response geometry, no particle left inside, the
// candidate-list refresh, and the candidate lists + temporal coherence finding exactly what
// brute force finds (skirt and dress, normal and fast walks).
#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <functional>

#include "analytic_body.hpp"
#include "drape/systems/cloth/body.hpp"
#include "drape/systems/cloth/collision.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_step.hpp"
#include "drape/systems/cloth/substeps.hpp"

namespace drape {
namespace {

EllipsoidFrame tilted_ellipsoid() {
    Affine3 t = Affine3::Identity();
    t.translate(Vec3(0.3f, 1.2f, -0.4f));
    t.rotate(Eigen::AngleAxis<Real>(0.7f, Vec3(1, 2, 3).normalized()));
    t.scale(Vec3(0.2f, 0.1f, 0.35f));
    EllipsoidFrame f = make_ellipsoid_frame(t);
    f.velocity_m_s = Vec3(0.5f, 0, 0);
    return f;
}

TEST(Collision, ResponseMovesOntoTheSurfaceAlongTheCentreLineAndRemovesNormalVelocity) {
    const EllipsoidFrame f = tilted_ellipsoid();
    for (const Vec3& local : {Vec3(0.3f, 0.2f, -0.5f), Vec3(-0.1f, 0.6f, 0.2f), Vec3(0.05f, -0.02f, 0.9f)}) {
        Vec3 x = f.center + f.rotation * f.radii_m.cwiseProduct(local);
        const Vec3 x0 = x;
        Vec3 v(-3, 1, 2);
        const Vec3 y = to_unit_sphere(f, x);
        ASSERT_LT(y.norm(), 1);
        push_out(f, y, x, v);
        EXPECT_NEAR(to_unit_sphere(f, x).norm(), 1, 1e-4);  // a hair outside (float clearance)
        // On the line from the centre through the old position, beyond it.
        const Vec3 a = (x0 - f.center).normalized(), b = (x - f.center).normalized();
        EXPECT_GT(a.dot(b), 1 - 1e-5);
        EXPECT_GT((x - f.center).norm(), (x0 - f.center).norm());
        // No velocity into the surface relative to the moving ellipsoid.
        const Vec3 normal = (f.to_unit.transpose() * to_unit_sphere(f, x)).normalized();
        EXPECT_GE((v - body_velocity_at(f, x)).dot(normal), -1e-5);
        EXPECT_EQ(penetration_depth(f, x), 0);
    }
}

TEST(Collision, OverlappingEllipsoidsLeaveNoParticleInside) {
    // Three ellipsoids overlapping at a crease; particles sprinkled through them.
    std::vector<EllipsoidFrame> frames;
    for (int i = 0; i < 3; ++i) {
        Affine3 t = Affine3::Identity();
        t.translate(Vec3(Real(0.12) * Real(i), Real(0.05) * Real(i % 2), 0));
        t.rotate(Eigen::AngleAxis<Real>(Real(0.5) * Real(i), Vec3::UnitZ()));
        t.scale(Vec3(0.15f, 0.08f, 0.1f));
        frames.push_back(make_ellipsoid_frame(t));
    }
    const int n = 2000;
    Matrix3X x(3, n), v = Matrix3X::Zero(3, n);
    std::uint32_t state = 12345;
    auto uniform = [&] {
        state = state * 1664525u + 1013904223u;
        return Real(state >> 8) / Real(1 << 24);
    };
    for (int p = 0; p < n; ++p) x.col(p) = Vec3(-0.15f + 0.5f * uniform(), -0.15f + 0.3f * uniform(), -0.1f + 0.2f * uniform());
    const VectorX inv_mass = VectorX::Ones(n);
    std::vector<std::uint64_t> last;
    const CollisionResult r = collide_particles(x, v, inv_mass, frames, nullptr, last);
    EXPECT_GT(r.collisions, 500u);
    EXPECT_EQ(r.unresolved, 0u);
    for (int p = 0; p < n; ++p)
        for (const EllipsoidFrame& f : frames) ASSERT_LE(penetration_depth(f, x.col(p)), 1e-5) << "particle " << p;
}

// A particle caught where two spheres overlap, in neither's reach of the surface along its
// own normals and centre lines (it leaves them only through the other sphere), while the
// cloth above it lies outside both: it leaves toward that cloth, by the short way, and not
// through a sphere.
TEST(Collision, ACaughtParticleLeavesTowardTheParticleAboveIt) {
    std::vector<EllipsoidFrame> frames;
    for (const Real centre : {Real(0), Real(0.35)}) {
        Affine3 t = Affine3::Identity();
        t.translate(Vec3(centre, 1, 0));
        t.scale(Real(0.3));
        frames.push_back(make_ellipsoid_frame(t));
    }
    const Vec3 caught(0.175f, 1, 0), cloth(0.175f, 1.3f, 0);  // the cloth above: outside both
    for (const EllipsoidFrame& f : frames) ASSERT_EQ(penetration_depth(f, cloth), 0);
    const auto leave = [&](bool with_above) {
        Matrix3X x(3, 2), v = Matrix3X::Zero(3, 2);
        x.col(0) = cloth;
        x.col(1) = caught;
        VectorX inv_mass(2);
        inv_mass << 0, 1;  // the particle above is pinned here
        std::vector<std::uint64_t> last;
        const std::vector<std::uint32_t> above = {0, 0};
        const CollisionResult r = collide_particles(x, v, inv_mass, frames, nullptr, last, nullptr, 0, {}, 0, -1, false,
                                                    with_above ? std::span<const std::uint32_t>(above) : std::span<const std::uint32_t>());
        EXPECT_EQ(r.unresolved, 0u);
        for (const EllipsoidFrame& f : frames) EXPECT_LE(penetration_depth(f, x.col(1)), 1e-5);
        return Vec3(x.col(1));
    };
    // The spheres meet on a circle of radius sqrt(0.3^2 - 0.175^2) = 0.244 m around the
    // particle: toward the cloth it leaves there, 0.244 m up.
    const Vec3 out = leave(true);
    EXPECT_NEAR((out - caught).norm(), 0.2437f, 0.002f);
    EXPECT_GT(out.y(), caught.y());
    // Without that way it leaves along the centre line, through the other sphere, farther.
    EXPECT_GT((leave(false) - caught).norm(), 0.4f);
}

// Attaches a garment to the analytic body's character.
using Dress = std::function<Entity(Registry&, Entity character, ClothModel, CollisionMode)>;

Entity default_skirt(Registry& registry, Entity character, ClothModel model, CollisionMode mode) {
    TubeParams params = TubeParams::skirt();
    params.model = model;
    params.collision = mode;
    return *attach_skirt(registry, character, params);
}

// A 2,520-particle dress (the default's layout at half the resolution: the test stays quick).
Entity small_dress(Registry& registry, Entity character, ClothModel model, CollisionMode mode) {
    TubeParams params = TubeParams::dress();
    params.warp_lines = 60;
    params.particles_per_line = 42;
    params.model = model;
    params.collision = mode;
    return *attach_dress(registry, character, params);
}

// A walk twice as fast with wider swings: a shin or a hand moves well past half the margin
// in one step relative to the pelvis.
test::WalkSettings fast_walk() {
    test::WalkSettings walk;
    walk.period_s = 0.55;
    walk.hip_swing_rad = 0.7;
    walk.knee_bend_rad = 1.1;
    walk.forward_speed_m_s = 3.0;
    walk.yaw_rad = 0.25;
    return walk;
}

// Walks a garment through a whole walk cycle, calling `check(garment, solver, before)` around
// every collision round.
template <class F>
void walk_cycle(ClothModel model, CollisionMode mode, F&& check, const Dress& dress = default_skirt,
                test::WalkSettings walk = {}) {
    Registry registry;
    test::AnalyticBody body(registry, walk);
    const Entity e = dress(registry, body.character, model, mode);
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& solver = registry.get<GarmentSolver>(e);
    const int frames = static_cast<int>(walk.period_s / (1.0 / 60.0)) + 1;
    test::step_by_hand(
        body, registry, g, solver, frames, test::StageCheck{},
        [&](Garment& garment, GarmentSolver& s, const ClothSubstep& ctx, int) {
            check(garment, s, /*before=*/true);
            collide_round(registry, garment, s, ctx, 0);
            check(garment, s, /*before=*/false);
        });
}

// Detection with lists + last-collided first, compared pair for pair with brute force on
// identical positions before every collision pass. Returns {contacts, list tests, brute tests}.
std::array<std::uint64_t, 3> compare_with_brute_force(ClothModel model, const Dress& dress, test::WalkSettings walk) {
    std::uint64_t contacts = 0, list_tests = 0, brute_tests = 0;
    walk_cycle(
        model, CollisionMode::candidate_lists,
        [&](Garment& g, GarmentSolver& s, bool before) {
            if (!before) return;
            const DetectedPairs expected = detect_brute_force(g.state.x, g.state.inv_mass, s.frames);
            Garment copy = g;
            GarmentSolver copy_solver = s;
            DetectedPairs found;
            const std::uint64_t tests_before = copy.counters.collision_tests;
            collide_garment(copy, copy_solver, &found);
            ASSERT_EQ(found.size(), expected.size());
            for (std::size_t p = 0; p < found.size(); ++p) ASSERT_EQ(found[p], expected[p]) << "particle " << p;
            for (std::uint64_t bits : expected) contacts += static_cast<std::uint64_t>(std::popcount(bits));
            list_tests += copy.counters.collision_tests - tests_before;
            brute_tests += static_cast<std::uint64_t>(g.state.x.cols()) * s.frames.size();
        },
        dress, walk);
    return {contacts, list_tests, brute_tests};
}

// Detection tests blocks of 64 particles in vector lanes; it must agree with the single
// unit-sphere test for every particle, including a last block that is not full and pinned
// particles (never reported).
// A hip (a sphere that does not give) and a forearm (a sphere with 3 cm of give) that
// overlap by 2 cm, as a fitted forearm's bulge overlaps the hips where its skin does not.
std::vector<EllipsoidFrame> hip_and_forearm(Real give_m) {
    std::vector<EllipsoidFrame> frames;
    for (const auto& [centre, radius] : {std::pair{Real(0), Real(0.15)}, std::pair{Real(0.19), Real(0.06)}}) {
        Affine3 t = Affine3::Identity();
        t.translate(Vec3(centre, 1, 0));
        t.scale(radius);
        frames.push_back(make_ellipsoid_frame(t));
    }
    frames[1].give_m = give_m;
    return frames;
}

// Collides one free particle at `start` against `frames`; returns where it ends.
Vec3 collide_alone(const std::vector<EllipsoidFrame>& frames, const Vec3& start) {
    Matrix3X x(3, 1), v = Matrix3X::Zero(3, 1);
    x.col(0) = start;
    std::vector<std::uint64_t> last;
    const CollisionResult r = collide_particles(x, v, VectorX::Ones(1), frames, nullptr, last);
    EXPECT_EQ(r.unresolved, 0u);
    return x.col(0);
}

TEST(Collision, CaughtBetweenTheHipsAndAForearmThatGivesClothKeepsToTheHips) {
    const Vec3 caught(0.14f, 1, 0);  // 1 cm inside the hip, 1 cm inside the forearm
    // With give: onto the hip's surface, left inside the forearm within its give.
    const std::vector<EllipsoidFrame> giving = hip_and_forearm(0.03f);
    const Vec3 kept = collide_alone(giving, caught);
    EXPECT_NEAR((kept - giving[0].center).norm(), 0.15f, 1e-4);
    EXPECT_EQ(penetration_depth(giving[0], kept), 0);
    EXPECT_GT(penetration_depth(giving[1], kept), 0.015f);
    EXPECT_LE(depth_past_give(giving, 1, kept), 1e-4);
    EXPECT_LT((kept - caught).norm(), 0.011f);
    // Without: squeezed out of both, farther from where it was.
    const std::vector<EllipsoidFrame> hard = hip_and_forearm(0);
    const Vec3 squeezed = collide_alone(hard, caught);
    for (const EllipsoidFrame& f : hard) EXPECT_LE(penetration_depth(f, squeezed), 1e-5);
    EXPECT_GT((squeezed - caught).norm(), 0.03f);
}

TEST(Collision, AGivingEllipsoidGivesOnlyNearOneThatDoesNot) {
    const std::vector<EllipsoidFrame> frames = hip_and_forearm(0.03f);
    // 9 cm outside the hip, 1 cm inside the forearm: no give that far out, pushed out whole.
    const Vec3 far = collide_alone(frames, Vec3(0.24f, 1, 0));
    EXPECT_EQ(penetration_depth(frames[1], far), 0);
    EXPECT_EQ(depth_past_give(frames, 1, Vec3(0.24f, 1, 0)), penetration_depth(frames[1], Vec3(0.24f, 1, 0)));
    // 1 cm outside the hip, 2 cm inside the forearm: its give there is 3 - 1 = 2 cm.
    const Vec3 near(0.16f, 1, 0.01f);
    EXPECT_NEAR(penetration_depth(frames[1], near) - depth_past_give(frames, 1, near), 0.02f, 0.002f);
    const Vec3 out = collide_alone(frames, near);
    EXPECT_LE(depth_past_give(frames, 1, out), 1e-4);
    EXPECT_EQ(penetration_depth(frames[0], out), 0);
    // A hip alone gives nothing: depth_past_give is its depth.
    EXPECT_EQ(depth_past_give(frames, 0, Vec3(0.1f, 1, 0)), penetration_depth(frames[0], Vec3(0.1f, 1, 0)));
}

TEST(Collision, BlockDetectionAgreesWithTheUnitSphereTestOfEachParticle) {
    std::vector<EllipsoidFrame> frames{tilted_ellipsoid()};
    Affine3 t = Affine3::Identity();
    t.translate(Vec3(0.35f, 1.15f, -0.3f));
    t.scale(Vec3(0.15f, 0.25f, 0.1f));
    frames.push_back(make_ellipsoid_frame(t));
    frames.push_back(frames[0]);
    frames.back().active = false;  // an inactive collider is never reported
    const Eigen::Index n = 64 * 5 + 5;  // a last block that is not full
    std::uint32_t state = 12345;
    const auto next = [&state] {
        state = state * 1664525u + 1013904223u;
        return Real(state >> 8) / Real(1 << 24);
    };
    Matrix3X x(3, n);
    VectorX inv_mass = VectorX::Ones(n);
    for (Eigen::Index p = 0; p < n; ++p) {
        x.col(p) = Vec3(0.3f, 1.2f, -0.4f) + Real(0.8) * Vec3(next() - Real(0.5), next() - Real(0.5), next() - Real(0.5));
        if (p % 17 == 0) inv_mass[p] = 0;
    }
    const DetectedPairs found = detect_brute_force(x, inv_mass, frames);
    int hits = 0, checked = 0;
    for (Eigen::Index p = 0; p < n; ++p) {
        const std::uint64_t bits = found[static_cast<std::size_t>(p)];
        if (inv_mass[p] == 0) {
            EXPECT_EQ(bits, 0u) << "pinned particle " << p;
            continue;
        }
        EXPECT_EQ(bits & 4u, 0u) << "inactive collider, particle " << p;
        for (std::size_t e = 0; e < 2; ++e) {
            const Real y_sq = to_unit_sphere(frames[e], x.col(p)).squaredNorm();
            if (std::abs(y_sq - 1) < Real(1e-5)) continue;  // a float rounding apart from the surface
            ++checked;
            const bool inside = y_sq < 1;
            hits += inside;
            EXPECT_EQ((bits >> e) & 1u, inside ? 1u : 0u) << "particle " << p << " ellipsoid " << e;
        }
    }
    EXPECT_GT(hits, 20);
    EXPECT_GT(checked - hits, 20);
}

TEST(CandidateLists, ARefreshedBitHoldsEveryPointWithinTheMarginAndOnlyItsBitChanges) {
    const EllipsoidFrame f = tilted_ellipsoid();
    const std::vector<EllipsoidFrame> frames = {tilted_ellipsoid(), f};  // refresh bit 1
    const Real margin = Real(0.08);
    std::uint32_t state = 7;
    auto uniform = [&] {
        state = state * 1664525u + 1013904223u;
        return Real(state >> 8) / Real(1 << 24);
    };
    const int n = 3000;
    Matrix3X x(3, n);
    std::vector<Real> offset(n);  // distance outside the surface along its normal; < margin for the first half
    for (int p = 0; p < n; ++p) {
        Vec3 u(uniform() - Real(0.5), uniform() - Real(0.5), uniform() - Real(0.5));
        u.normalize();
        const Vec3 surface = f.center + f.rotation * f.radii_m.cwiseProduct(u);
        const Vec3 normal = (f.to_unit.transpose() * u).normalized();
        offset[std::size_t(p)] = p < n / 2 ? margin * uniform() * Real(0.999) : margin + Real(0.5) * uniform();
        x.col(p) = surface + offset[std::size_t(p)] * normal;
    }
    std::vector<std::uint64_t> candidates(n);
    for (int p = 0; p < n; ++p) candidates[std::size_t(p)] = (p % 3 == 0 ? 0b1u : 0u) | (p % 2 == 0 ? 0b10u : 0u) | 0b100u;
    const std::vector<std::uint64_t> before = candidates;
    EXPECT_GT(refresh_candidate_bit(x, frames, 1, margin, candidates), 0u);
    int cleared = 0;
    for (int p = 0; p < n; ++p) {
        const std::size_t i = std::size_t(p);
        EXPECT_EQ(candidates[i] & ~std::uint64_t(0b10), before[i] & ~std::uint64_t(0b10)) << "point " << p;  // others kept
        if (p < n / 2) {
            EXPECT_TRUE(candidates[i] & 0b10) << "point " << p << " is " << offset[i] << " m outside";
        }
        // Beyond the margin on one of its own axes the point cannot be within the margin.
        const Vec3 local = f.rotation.transpose() * (x.col(p) - f.center);
        if (((local.cwiseAbs() - f.radii_m).array() > margin).any()) {
            EXPECT_FALSE(candidates[i] & 0b10) << "point " << p;
        }
        cleared += (candidates[i] & 0b10) == 0;
    }
    EXPECT_GT(cleared, n / 4);  // the far half is mostly left out

    // An inactive ellipsoid: the bit is cleared everywhere, without a test.
    std::vector<EllipsoidFrame> gone = frames;
    gone[1].active = false;
    EXPECT_EQ(refresh_candidate_bit(x, gone, 1, margin, candidates), 0u);
    for (int p = 0; p < n; ++p) EXPECT_EQ(candidates[std::size_t(p)], before[std::size_t(p)] & ~std::uint64_t(0b10));
}

TEST(CandidateLists, OnASphereTheListIsExactlyTheMarginShell) {
    // For a sphere the clearance bound is the distance itself: listed <=> |x - c| - r <= margin.
    Affine3 t = Affine3::Identity();
    t.translate(Vec3(0.1f, 1.0f, 0.2f));
    t.scale(Real(0.15));
    const std::vector<EllipsoidFrame> frames = {make_ellipsoid_frame(t)};
    const Real margin = Real(0.08);
    Matrix3X x(3, 200);
    for (int p = 0; p < 200; ++p) {
        const Real distance = Real(0.15) + Real(0.0013) * Real(p) - Real(0.05);  // -0.05 .. 0.21 m from the surface
        x.col(p) = frames[0].center + distance * Vec3(1, 2, -2).normalized();
    }
    std::vector<std::uint64_t> candidates;
    build_candidate_lists(x, frames, margin, candidates);
    for (int p = 0; p < 200; ++p) {
        const Real gap = (x.col(p) - frames[0].center).norm() - Real(0.15);
        if (std::abs(gap - margin) < Real(1e-5)) continue;  // float rounding at the boundary
        EXPECT_EQ(candidates[std::size_t(p)] == 1, gap <= margin) << "gap " << gap;
    }
}

TEST(CandidateLists, OnlyTheEllipsoidsThatMovedAreRefreshed) {
    // A skirt on a motionless body: after the first build nothing is refreshed. Then one
    // forearm (far below the waist, beside the hips) swings by more than half the margin:
    // only its bit is refreshed, and blocks of particles far from it are not even tested.
    Registry registry;
    test::WalkSettings still;
    still.hip_swing_rad = still.knee_bend_rad = still.forward_speed_m_s = still.yaw_rad = 0;
    test::AnalyticBody body(registry, still);
    const Entity e = default_skirt(registry, body.character, ClothModel::simplified, CollisionMode::candidate_lists);
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& solver = registry.get<GarmentSolver>(e);
    update_frames(registry, g.body, solver.frames, 1);
    solver.lists.valid = false;
    update_candidate_lists(g, solver);
    const std::uint64_t rebuilds = g.counters.list_rebuilds;
    const std::uint64_t full = g.counters.list_rebuild_tests;
    EXPECT_GT(full, 0u);
    update_candidate_lists(g, solver);
    EXPECT_EQ(g.counters.list_rebuild_tests, full);  // nothing moved: nothing refreshed

    const Entity forearm_entity = body.colliders[6];  // analytic body: left forearm
    std::size_t forearm = 0;
    while (forearm < g.body.colliders.size() && g.body.colliders[forearm] != forearm_entity) ++forearm;
    ASSERT_LT(forearm, g.body.colliders.size());
    auto& c = registry.get<EllipsoidCollider>(forearm_entity);
    c.world.translation() += Vec3(0, 0, Real(0.06));  // 6 cm > margin / 2 = 4 cm
    update_frames(registry, g.body, solver.frames, 1);
    const std::vector<std::uint64_t> lists = solver.lists.bits;
    update_candidate_lists(g, solver);
    EXPECT_EQ(g.counters.list_rebuilds, rebuilds);                                    // no full rebuild
    EXPECT_LT(g.counters.list_rebuild_tests - full, static_cast<std::uint64_t>(g.state.x.cols()));  // part of one bit
    const std::uint64_t others = ~(std::uint64_t(1) << forearm);
    for (std::size_t p = 0; p < lists.size(); ++p) EXPECT_EQ(solver.lists.bits[p] & others, lists[p] & others);
    // And the lists still find exactly what brute force finds.
    const DetectedPairs expected = detect_brute_force(g.state.x, g.state.inv_mass, solver.frames);
    DetectedPairs found;
    Garment copy = g;
    GarmentSolver copy_solver = solver;
    collide_garment(copy, copy_solver, &found);
    EXPECT_EQ(found, expected);
}

class CollisionOnWalk : public ::testing::TestWithParam<ClothModel> {};

TEST_P(CollisionOnWalk, NoFreeParticleInsideAnyEllipsoidAfterCollision) {
    std::uint64_t collisions = 0;
    walk_cycle(GetParam(), CollisionMode::candidate_lists, [&](Garment& g, GarmentSolver& s, bool before) {
        if (before) return;
        collisions = g.counters.collisions;
        for (Eigen::Index p = 0; p < g.state.x.cols(); ++p) {
            if (g.state.inv_mass[p] == 0) continue;
            EXPECT_EQ(g.counters.unresolved, 0u);
            for (std::size_t e = 0; e < s.frames.size(); ++e)
                ASSERT_LE(penetration_depth(s.frames[e], g.state.x.col(p)), 1e-5)
                    << "particle " << p << " ellipsoid " << e << " list " << std::hex << s.lists.bits[std::size_t(p)]
                    << " last " << s.last_collided[std::size_t(p)];
        }
    });
    EXPECT_GT(collisions, 100u);
}

TEST_P(CollisionOnWalk, CandidateListsAndTemporalCoherenceFindExactlyWhatBruteForceFinds) {
    const auto [contacts, list_tests, brute_tests] = compare_with_brute_force(GetParam(), default_skirt, {});
    EXPECT_GT(contacts, 1000u);              // the cycle really collides
    EXPECT_LT(list_tests, brute_tests / 2);  // and the lists really prune
}

TEST_P(CollisionOnWalk, CandidateListsStayExactOnAFastWalk) {
    const auto [contacts, list_tests, brute_tests] = compare_with_brute_force(GetParam(), default_skirt, fast_walk());
    EXPECT_GT(contacts, 1000u);
    EXPECT_LT(list_tests, brute_tests / 2);
}

TEST_P(CollisionOnWalk, CandidateListsStayExactOnADress) {
    const auto [contacts, list_tests, brute_tests] = compare_with_brute_force(GetParam(), small_dress, {});
    EXPECT_GT(contacts, 1000u);
    EXPECT_LT(list_tests, brute_tests / 2);
}

TEST_P(CollisionOnWalk, AParticleMovedByItsSlackStaysOutOfEveryEllipsoidItsListLeavesOut) {
    // The slack is what the list bound still covers: within it, no unlisted ellipsoid can
    // be reached, in any direction (14 directions tried, plus straight at each ellipsoid).
    std::array<Vec3, 14> directions;
    std::size_t k = 0;
    for (int axis = 0; axis < 3; ++axis) {
        directions[k++] = Vec3::Unit(axis);
        directions[k++] = -Vec3::Unit(axis);
    }
    for (int sx = -1; sx <= 1; sx += 2)
        for (int sy = -1; sy <= 1; sy += 2)
            for (int sz = -1; sz <= 1; sz += 2) directions[k++] = Vec3(Real(sx), Real(sy), Real(sz)).normalized();
    std::uint64_t checked = 0;
    walk_cycle(
        GetParam(), CollisionMode::candidate_lists,
        [&](Garment& g, GarmentSolver& s, bool before) {
            if (!before) return;
            Garment copy = g;
            GarmentSolver copy_solver = s;
            update_candidate_lists(copy, copy_solver);
            ASSERT_EQ(copy_solver.lists.slack_m.size(), copy.state.x.cols());
            for (Eigen::Index p = 0; p < copy.state.x.cols(); ++p) {
                if (copy.state.inv_mass[p] == 0) continue;
                const Real slack = copy_solver.lists.slack_m[p];
                ASSERT_GE(slack, 0) << "particle " << p;
                const std::uint64_t unlisted = active_mask(copy_solver.frames) & ~copy_solver.lists.bits[static_cast<std::size_t>(p)];
                for (std::size_t e = 0; e < copy_solver.frames.size(); ++e) {
                    if (!(unlisted >> e & 1)) continue;
                    const EllipsoidFrame& f = copy_solver.frames[e];
                    const Vec3 x = copy.state.x.col(p);
                    const Vec3 toward = (f.center - x).normalized();
                    ASSERT_GE(to_unit_sphere(f, x + slack * toward).squaredNorm(), 1) << "particle " << p << " ellipsoid " << e;
                    for (const Vec3& d : directions)
                        ASSERT_GE(to_unit_sphere(f, x + slack * d).squaredNorm(), 1) << "particle " << p << " ellipsoid " << e;
                    ++checked;
                }
            }
        },
        default_skirt, fast_walk());
    EXPECT_GT(checked, 100000u);
}

INSTANTIATE_TEST_SUITE_P(Models, CollisionOnWalk, ::testing::Values(ClothModel::simplified, ClothModel::classic),
                         [](const auto& info) { return info.param == ClothModel::simplified ? "simplified" : "classic"; });

TEST(Collision, BruteForceAndListsGiveTheSameGarmentOnAStaticBody) {
    // With nothing moving between list builds the two modes resolve the same contacts.
    auto run = [](CollisionMode mode) {
        Registry registry;
        test::WalkSettings still;
        still.hip_swing_rad = still.knee_bend_rad = still.forward_speed_m_s = still.yaw_rad = 0;
        test::AnalyticBody body(registry, still);
        TubeParams params = TubeParams::skirt();
        params.collision = mode;
        const Entity e = *attach_skirt(registry, body.character, params);
        Scheduler scheduler;
        scheduler.add(body.system(registry));
        add_cloth_systems(scheduler);
        for (int i = 0; i < 30; ++i) (void)scheduler.tick(registry, 1.0 / 60.0);
        const Garment& g = registry.get<Garment>(e);
        return std::pair{g.counters.collisions, Matrix3X(g.state.x)};
    };
    const auto [list_collisions, with_lists] = run(CollisionMode::candidate_lists);
    const auto [brute_collisions, brute] = run(CollisionMode::brute_force);
    EXPECT_GT(list_collisions, 0u);
    EXPECT_EQ(list_collisions, brute_collisions);
    ASSERT_EQ(with_lists.cols(), brute.cols());
    EXPECT_LT((with_lists - brute).cwiseAbs().maxCoeff(), 1e-5f);
}

}  // namespace
}  // namespace drape
