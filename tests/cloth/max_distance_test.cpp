// The max distance (GarmentConfig::max_distance_share; constraints.hpp solve_max_distance):
// each particle hung from a pin is kept within share x its tether's length of its place in
// the rest shape, as the anchor carries that shape.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "analytic_body.hpp"
#include "drape/systems/cloth/constraints.hpp"
#include "drape/systems/cloth/garment_builder.hpp"

namespace drape {
namespace {

TEST(MaxDistance, AParticleOutsideItsSphereGoesOntoItOneInsideStays) {
    // Three particles: 0 is the pin, 1 and 2 hang 0.2 m and 0.5 m below it on its line.
    Matrix3X rest_local(3, 3);
    rest_local << 0, 0, 0,
                  0, Real(-0.2), Real(-0.5),
                  0, 0, 0;
    Tethers tethers;
    tethers.particle = {1, 2};
    tethers.anchor = {0, 0};
    tethers.length_m = {Real(0.2), Real(0.5)};
    // The anchor turned a quarter turn about z and moved: the rest places go with it.
    Affine3 anchor = Affine3::Identity();
    anchor.translate(Vec3(1, 2, 3));
    anchor.rotate(Eigen::AngleAxis<Real>(std::numbers::pi_v<Real> / 2, Vec3::UnitZ()));
    const Vec3 place1 = anchor * Vec3(rest_local.col(1)), place2 = anchor * Vec3(rest_local.col(2));
    EXPECT_TRUE(place1.isApprox(Vec3(Real(1.2), 2, 3), Real(1e-5)));

    Matrix3XRows x(3, 3);
    x.col(0) = anchor * Vec3(rest_local.col(0));
    x.col(1) = place1 + Vec3(0, Real(0.1), 0);  // 0.1 m from its place: inside 0.2
    x.col(2) = place2 + Vec3(0, Real(0.9), 0);  // 0.9 m above its place: outside 0.5, above the pin
    const Vec3 x1 = x.col(1);
    solve_max_distance(tethers, rest_local, anchor, 1, x);
    EXPECT_TRUE(Vec3(x.col(1)).isApprox(x1));
    EXPECT_NEAR((Vec3(x.col(2)) - place2).norm(), 0.5, 1e-5);
    EXPECT_TRUE((Vec3(x.col(2)) - place2).normalized().isApprox(Vec3::UnitY(), Real(1e-5)));  // along the way it was
    EXPECT_TRUE(Vec3(x.col(0)).isApprox(anchor * Vec3(rest_local.col(0))));  // the pin is no tether's particle

    // Half the share: the sphere is half as wide.
    x.col(2) = place2 + Vec3(Real(0.6), 0, 0);
    solve_max_distance(tethers, rest_local, anchor, Real(0.5), x);
    EXPECT_NEAR((Vec3(x.col(2)) - place2).norm(), 0.25, 1e-5);
    EXPECT_NEAR((Vec3(x.col(1)) - place1).norm(), 0.1, 1e-5);  // within 0.1 still

    // Share 0 is off.
    x.col(2) = place2 + Vec3(0, 5, 0);
    solve_max_distance(tethers, rest_local, anchor, 0, x);
    EXPECT_NEAR((Vec3(x.col(2)) - place2).norm(), 5, 1e-4);
}

// On the skin (GarmentConfig::max_distance_on_skin) each centre is given per particle, at the
// start and the end of the fixed step; a substep takes its share of the way between them, and
// a centre the skin carried above the anchor's place for it is lowered to that height.
TEST(MaxDistance, CentresGivenPerParticleAreTakenAtTheSubstepsShareOfTheStepNeverAboveTheAnchors) {
    Tethers tethers;
    tethers.particle = {1, 2};
    tethers.anchor = {0, 0};
    tethers.length_m = {Real(0.2), Real(0.5)};
    Matrix3X previous = Matrix3X::Zero(3, 3), target = Matrix3X::Zero(3, 3);
    previous.col(1) = Vec3(0, Real(-0.2), 0);
    target.col(1) = Vec3(Real(0.4), Real(-0.2), 0);  // carried 0.4 m along x over the step
    previous.col(2) = target.col(2) = Vec3(0, Real(-0.5), 0);
    Matrix3X rest_local = previous;  // the anchor's places: where the step started
    const Affine3 anchor = Affine3::Identity();
    Matrix3XRows x(3, 3);
    x.col(0) = Vec3::Zero();
    x.col(1) = Vec3(0, Real(-0.2), 0);              // at its centre at the start of the step
    x.col(2) = Vec3(0, Real(-0.3), 0);              // 0.2 m from its centre: inside 0.5
    // A quarter of the way: the centre at x = 0.1, within 0.2 of it: stays.
    solve_max_distance(tethers, previous, target, Real(0.25), rest_local, anchor, 1, x);
    EXPECT_TRUE(Vec3(x.col(1)).isApprox(Vec3(0, Real(-0.2), 0)));
    // The whole way: the centre at x = 0.4, 0.4 away: pulled onto its sphere toward it.
    solve_max_distance(tethers, previous, target, 1, rest_local, anchor, 1, x);
    EXPECT_TRUE(Vec3(x.col(1)).isApprox(Vec3(Real(0.2), Real(-0.2), 0), Real(1e-5))) << Vec3(x.col(1)).transpose();
    EXPECT_TRUE(Vec3(x.col(2)).isApprox(Vec3(0, Real(-0.3), 0)));
    // A leg lifts particle 2's centre 0.6 m, to 0.1 m above the pin: the sphere stays at the
    // anchor's height, 0.5 m under the pin, and a particle lifted with the leg comes down onto it.
    target.col(2) = Vec3(0, Real(0.1), 0);
    x.col(2) = Vec3(0, Real(0.1), 0);
    solve_max_distance(tethers, target, target, 1, rest_local, anchor, 1, x);
    EXPECT_LT(Vec3(x.col(2)).norm(), 1e-5) << Vec3(x.col(2)).transpose();  // onto the pin's height
    // Centres for another number of particles: nothing is done.
    x.col(1) = Vec3(5, 5, 5);
    solve_max_distance(tethers, Matrix3X::Zero(3, 2), Matrix3X::Zero(3, 2), 1, rest_local, anchor, 1, x);
    EXPECT_TRUE(Vec3(x.col(1)).isApprox(Vec3(5, 5, 5)));
}

// On a body without a skin (the analytic body: ellipsoids only) there is nothing to bind the
// spheres to: the anchor carries them, the skirt moving exactly as one built that way.
TEST(MaxDistance, OnTheSkinWithoutASkinTheAnchorCarriesTheSpheres) {
    Matrix3X x[2];
    for (int on_skin = 0; on_skin < 2; ++on_skin) {
        Registry registry;
        test::AnalyticBody body(registry);
        TubeParams params = TubeParams::skirt();
        params.max_distance_share = Real(0.5);
        params.max_distance_on_skin = on_skin;
        const Entity e = *attach_skirt(registry, body.character, params);
        Garment& g = registry.get<Garment>(e);
        GarmentSolver& solver = registry.get<GarmentSolver>(e);
        EXPECT_EQ(g.config.max_distance_on_skin, on_skin == 1);
        EXPECT_TRUE(g.body.rest_on_skin.empty());
        test::step_by_hand(body, registry, g, solver, 60);
        EXPECT_EQ(solver.sphere_target.cols(), 0);
        EXPECT_TRUE(g.state.x.allFinite());
        x[on_skin] = g.state.x;
    }
    EXPECT_EQ(x[0], x[1]);
}

}  // namespace
}  // namespace drape
