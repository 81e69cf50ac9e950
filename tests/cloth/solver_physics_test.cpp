// The solver's physics as physics: every mass counted once, a round budget that is counted
// when it binds.
#include <gtest/gtest.h>

#include "analytic_body.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_quality.hpp"
#include "drape/systems/cloth/garment_step.hpp"

namespace drape {
namespace {

double total_mass(const VectorX& inv_mass) {
    double m = 0;
    for (Eigen::Index i = 0; i < inv_mass.size(); ++i)
        if (inv_mass[i] > 0) m += 1.0 / double(inv_mass[i]);
    return m;
}

// The constraint rounds see each particle with its own mass: the garment's free mass in the
// solver is the garment's free mass (a layer-2 particle's mass added to its layer-1
// neighbours as well as kept on it would count it twice).
TEST(SolverMasses, EveryMassIsCountedOnce) {
    for (ClothModel model : {ClothModel::simplified, ClothModel::classic}) {
        Registry registry;
        test::AnalyticBody body(registry);
        TubeParams params = TubeParams::skirt();
        params.model = model;
        const Entity e = *attach_skirt(registry, body.character, params);
        Garment& g = registry.get<Garment>(e);
        GarmentSolver& s = registry.get<GarmentSolver>(e);
        prepare_solver(g, s);
        const double garment = total_mass(g.state.inv_mass);
        ASSERT_GT(garment, 0);
        EXPECT_NEAR(total_mass(s.inv_mass), garment, 1e-4 * garment) << (model == ClothModel::simplified ? "simplified" : "classic");
    }
}

// The contact repair's round budget binds and is counted: with no rounds in the budget, a
// skirt on a walking body leaves springs over the limit after its substeps' last collision
// at least once, and each such substep is a budget hit; with the shipped budget the hits
// are fewer.
TEST(SolverBudget, RepairRoundsStopAtTheBudgetAndTheHitsAreCounted) {
    std::uint64_t hits[2] = {};
    for (int budget : {0, 1}) {
        Registry registry;
        test::AnalyticBody body(registry);
        const Entity e = *attach_skirt(registry, body.character, TubeParams::skirt());
        Garment& g = registry.get<Garment>(e);
        GarmentSolver& s = registry.get<GarmentSolver>(e);
        ClothSolverSettings settings;
        if (budget == 0) settings.repair_rounds_per_frame = 0;
        for (int frame = 0; frame < 120; ++frame) {
            body.place(registry, (frame + 1) / 60.0, false, 1.0 / 60.0);
            step_garment(registry, g, s, 1.0 / 60.0, settings);
            if (frame >= 10 && budget == 0) {
                EXPECT_EQ(g.counters.frame_repair_rounds, 0) << "frame " << frame;
            }
        }
        hits[budget] = g.counters.budget_hits;
    }
    EXPECT_GT(hits[0], 0u);
    EXPECT_LT(hits[1], hits[0]);
}

}  // namespace
}  // namespace drape

namespace drape {
namespace {

// The rise above the pins is measured along the body's up: a garment on a body lying on its
// side (a fall) whose hem hangs toward the feet does not rise, however high it is in the
// world; a particle past the pins toward the head does.
TEST(GarmentQualityRise, IsMeasuredAlongTheBodysUp) {
    Garment g;
    g.fabric = std::make_shared<Fabric>();
    g.body.anchor = 0;
    g.body.rest_local.resize(3, 3);
    g.body.rest_local << 0, 0.1f, -0.1f,   //
        0, -0.5f, -0.3f,                   //
        0, 0, 0;
    g.state.inv_mass = VectorX::Ones(3);
    g.state.inv_mass[0] = 0;  // the pin, at the anchor's centre
    EllipsoidFrame anchor;
    anchor.active = true;
    anchor.center = Vec3(0, 0.3f, 0);
    anchor.rotation = Eigen::AngleAxis<Real>(Real(EIGEN_PI / 2), Vec3::UnitZ()).toRotationMatrix();  // body up -> world -X
    const std::vector<EllipsoidFrame> frames = {anchor};
    const Mat3 R = anchor.rotation;
    // Lying down: the hem toward the feet (+X in the world), one particle 0.2 m above the pin
    // in the world but beside it along the body.
    g.state.x.resize(3, 3);
    g.state.x.col(0) = anchor.center;
    g.state.x.col(1) = R * Vec3(0, -0.5f, 0) + anchor.center;
    g.state.x.col(2) = anchor.center + Vec3(0, 0.2f, 0);
    g.state.v = Matrix3X::Zero(3, 3);
    EXPECT_NEAR(body_up(g, frames).x(), -1, 1e-5);
    EXPECT_NEAR(measure_garment(g, frames).rise_above_pins_m, 0, 1e-6);
    // Flung toward the head: 0.2 m past the pin along the body.
    g.state.x.col(2) = R * Vec3(0, 0.2f, 0) + anchor.center;
    EXPECT_NEAR(measure_garment(g, frames).rise_above_pins_m, 0.2, 1e-5);
    // Without an anchor the world's up is the body's.
    g.body.anchor = -1;
    EXPECT_NEAR(measure_garment(g, frames).rise_above_pins_m, 0, 1e-5);
}

}  // namespace
}  // namespace drape
