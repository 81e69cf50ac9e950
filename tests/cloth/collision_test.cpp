// Ellipsoid collision (method §5): response geometry, no particle left inside, and the
// candidate lists + temporal coherence finding exactly what brute force finds.
#include <gtest/gtest.h>

#include <bit>

#include "analytic_body.hpp"
#include "systems/cloth/body.hpp"
#include "systems/cloth/collision.hpp"
#include "systems/cloth/garment_builder.hpp"
#include "systems/cloth/garment_step.hpp"
#include "systems/cloth/substeps.hpp"

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

// Walks a skirt through a whole walk cycle, calling `check` around every collision pass.
template <class F>
void walk_cycle(ClothModel model, CollisionMode mode, F&& check) {
    Registry registry;
    test::WalkSettings walk;
    test::AnalyticBody body(registry, walk);
    SkirtParams params;
    params.model = model;
    params.collision = mode;
    const Entity e = *attach_skirt(registry, body.character, params);
    Garment& g = registry.get<Garment>(e);
    const double dt = 1.0 / 60.0;
    const int frames = static_cast<int>(walk.period_s / dt) + 1;
    for (int frame = 0; frame < frames; ++frame) {
        body.place(registry, (frame + 1) * dt, false, dt);
        const int substeps = garment_substeps(registry, g, dt, ClothSolverSettings{});
        FrameContext ctx;
        ctx.fixed_dt_s = dt;
        ctx.substeps = substeps;
        ctx.h_s = dt / substeps;
        for (int s = 0; s < substeps; ++s) {
            ctx.substep = s;
            integrate_garment(registry, g, ctx);
            constrain_garment(g, ctx);
            update_frames(registry, g, Real(s + 1) / Real(substeps));
            check(g, /*before=*/true);
            const CollisionResult r = collide_garment(g, nullptr, static_cast<Real>(ctx.h_s));
            g.counters.unresolved += r.unresolved;
            check(g, /*before=*/false);
        }
    }
}

class CollisionOnWalk : public ::testing::TestWithParam<ClothModel> {};

TEST_P(CollisionOnWalk, NoFreeParticleInsideAnyEllipsoidAfterCollision) {
    std::uint64_t collisions = 0;
    walk_cycle(GetParam(), CollisionMode::candidate_lists, [&](Garment& g, bool before) {
        if (before) return;
        collisions = g.counters.collisions;
        for (Eigen::Index p = 0; p < g.x.cols(); ++p) {
            if (g.inv_mass[p] == 0) continue;
            EXPECT_EQ(g.counters.unresolved, 0u);
            for (std::size_t e = 0; e < g.frames.size(); ++e)
                ASSERT_LE(penetration_depth(g.frames[e], g.x.col(p)), 1e-5)
                    << "particle " << p << " ellipsoid " << e << " list " << std::hex << g.candidates[std::size_t(p)]
                    << " last " << g.last_collided[std::size_t(p)];
        }
    });
    EXPECT_GT(collisions, 100u);
}

TEST_P(CollisionOnWalk, CandidateListsAndTemporalCoherenceFindExactlyWhatBruteForceFinds) {
    std::uint64_t contacts = 0, list_tests = 0, brute_tests = 0;
    // Detection as collide_garment does it, compared pair for pair on identical positions.
    walk_cycle(GetParam(), CollisionMode::candidate_lists, [&](Garment& g, bool before) {
        if (!before) return;
        const DetectedPairs expected = detect_brute_force(g.x, g.inv_mass, g.frames);
        Garment copy = g;
        DetectedPairs found;
        const std::uint64_t tests_before = copy.counters.collision_tests;
        collide_garment(copy, &found);
        ASSERT_EQ(found.size(), expected.size());
        for (std::size_t p = 0; p < found.size(); ++p) ASSERT_EQ(found[p], expected[p]) << "particle " << p;
        for (std::uint64_t bits : expected) contacts += static_cast<std::uint64_t>(std::popcount(bits));
        list_tests += copy.counters.collision_tests - tests_before;
        brute_tests += static_cast<std::uint64_t>(g.x.cols()) * g.frames.size();
    });
    EXPECT_GT(contacts, 1000u);      // the cycle really collides
    EXPECT_LT(list_tests, brute_tests / 2);  // and the lists really prune
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
        SkirtParams params;
        params.collision = mode;
        const Entity e = *attach_skirt(registry, body.character, params);
        Scheduler scheduler;
        scheduler.add(body.system(registry));
        add_cloth_systems(scheduler);
        for (int i = 0; i < 30; ++i) (void)scheduler.tick(registry, 1.0 / 60.0);
        return registry.get<Garment>(e).counters.collisions;
    };
    EXPECT_GT(run(CollisionMode::candidate_lists), 0u);
    EXPECT_GT(run(CollisionMode::brute_force), 0u);
}

}  // namespace
}  // namespace drape
