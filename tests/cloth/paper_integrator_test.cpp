// The paper's integrator (ClothIntegrator::paper, docs/cloth.md "Two integrators"): eq. 2's
// spring term as an explicit force, its stability bound, Provot's limit as Provot gives it,
// and what a stretch modulus does to a hanging sheet under it (and under the shipped solver
// with its warp lines solved directly).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "drape/systems/cloth/constraints.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/integrator.hpp"
#include "drape/systems/cloth_systems.hpp"

namespace drape {
namespace {

// One spring of stiffness k stretched by e: each free end's velocity changes by h k e / m
// toward the other; a pinned end's does not.
TEST(PaperIntegrator, SpringImpulseIsHookesForceOverTheStep) {
    SpringPhase spring;
    spring.add(0, 1, Real(0.1));
    SpringSet set;
    set.springs = &spring;
    set.compliance = {Real(1) / 500};  // k = 500 N/m
    Matrix3X x(3, 2);
    x.col(0) = Vec3(0, 0, 0);
    x.col(1) = Vec3(Real(0.12), 0, 0);  // 2 cm over rest
    const Real h = Real(0.001);
    for (const Real w0 : {Real(100), Real(0)}) {
        Matrix3X v = Matrix3X::Zero(3, 2);
        const VectorX w = (VectorX(2) << w0, Real(50)).finished();
        add_spring_impulses(set, x, w, h, v);
        EXPECT_NEAR(v(0, 0), w0 * h * 500 * Real(0.02), 1e-6);    // toward b
        EXPECT_NEAR(v(0, 1), -50 * h * 500 * Real(0.02), 1e-6);   // toward a
        EXPECT_EQ(v.row(1).norm() + v.row(2).norm(), 0);
    }
}

// The bound is exact where Gershgorin is: a particle on a spring to a pinned point,
// omega^2 = k / m, and two free particles on one spring, omega^2 = 2 k / m.
TEST(PaperIntegrator, StepBoundIsExactForOneSpring) {
    SpringPhase spring;
    spring.add(0, 1, Real(0.1));
    std::vector<SpringSet> sets(1);
    sets[0].springs = &spring;
    sets[0].compliance = {Real(1) / 400};
    const std::vector<std::size_t> all{0};
    const Real m = Real(0.01);
    EXPECT_NEAR(spring_step_limit_s(sets, all, (VectorX(2) << 0, 1 / m).finished()), 2 * std::sqrt(m / 400), 1e-6);
    EXPECT_NEAR(spring_step_limit_s(sets, all, (VectorX(2) << 1 / m, 1 / m).finished()), 2 * std::sqrt(m / 800), 1e-6);
    EXPECT_TRUE(std::isinf(spring_step_limit_s(sets, {}, VectorX::Constant(2, 1))));
}

// Provot's rule: back to (1 + limit) x rest, half each when both ends are free, all of it on
// the free end when the other is pinned; a spring within the limit is left alone.
TEST(PaperIntegrator, ProvotPassBringsASpringBackToItsLimit) {
    SpringPhase springs;
    springs.add(0, 1, 1);
    springs.add(2, 3, 1);
    springs.add(4, 5, 1);
    Matrix3X x = Matrix3X::Zero(3, 6);
    x(0, 1) = 2;                      // free - free, 100 % over
    x(0, 3) = 2;                      // pinned 2 - free 3
    x(0, 5) = Real(1.05);             // within 10 %
    const VectorX w = (VectorX(6) << 1, 1, 0, 1, 1, 1).finished();
    const Matrix3X before = x;
    EXPECT_EQ(provot_pass(springs, w, Real(0.1), x), 2u);
    EXPECT_NEAR(x(0, 0), Real(0.45), 1e-6);
    EXPECT_NEAR(x(0, 1), Real(1.55), 1e-6);
    EXPECT_EQ(x(0, 2), 0);
    EXPECT_NEAR(x(0, 3), Real(1.1), 1e-6);
    EXPECT_EQ(x.col(4), before.col(4));
    EXPECT_EQ(x.col(5), before.col(5));
}

// Mean strain of the top row's warp springs of a hanging sheet over its second second.
double hanging_top_strain(Real modulus, ClothIntegrator integrator, int* substeps = nullptr,
                          WarpSolve warp_solve = WarpSolve::rounds) {
    Registry registry;
    RectangleParams params;
    params.integrator = integrator;
    params.material.stretch_N_m = modulus;
    params.material.strain_limit = Real(0.5);  // far above what these moduli stretch to: the springs hold the sheet
    const Entity e = *attach_rectangle(registry, params);
    registry.get<Garment>(e).config.warp_solve = warp_solve;
    Scheduler scheduler;
    add_cloth_systems(scheduler);
    double sum = 0;
    int samples = 0;
    for (int frame = 0; frame < 120; ++frame) {
        EXPECT_TRUE(scheduler.tick(registry, 1.0 / 60.0));
        if (frame < 60) continue;
        const Garment& g = registry.get<Garment>(e);
        const Fabric& f = *g.fabric;
        for (std::size_t s = 0; s < f.warp1.size(); ++s) {
            if (g.state.inv_mass[f.warp1.a[s]] != 0) continue;  // the springs from the pinned row
            sum += double((g.state.x.col(f.warp1.b[s]) - g.state.x.col(f.warp1.a[s])).norm() / f.warp1.rest_m[s]) - 1;
            ++samples;
        }
        if (substeps) *substeps = g.counters.substeps;
    }
    return sum / std::max(1, samples);
}

// Under the paper's integrator the sheet's modulus is its stiffness: its top springs carry
// the weight of the sheet below, strain = areal density x g x length / modulus (0.17 x 9.81
// x 1 m / E: 8.3 % at 20 N/m, 0.083 % at 2,000 N/m), a third more at the top (the pinned row
// stands for half a row's area, so its springs are 3/4 as stiff: measured 10.5 % and 0.107 %).
// A hundred times the modulus, a hundredth of the strain; and the explicit step follows the
// stiffness: more substeps for the stiffer sheet (4 and 31).
TEST(PaperIntegrator, TheModulusSetsAHangingSheetsStrain) {
    int soft_substeps = 0, stiff_substeps = 0;
    const double soft = hanging_top_strain(20, ClothIntegrator::paper, &soft_substeps);
    const double stiff = hanging_top_strain(2000, ClothIntegrator::paper, &stiff_substeps);
    const double load = 0.17 * double(standard_gravity_m_s2) * 1.0;  // strain x E
    EXPECT_GT(soft, load / 20);
    EXPECT_LT(soft, 1.5 * load / 20);
    EXPECT_NEAR(soft / stiff, 100, 20);
    EXPECT_GT(stiff_substeps, soft_substeps);
}

// With its lines solved directly the shipped solver hangs the sheet as the paper's
// integrator does (PaperIntegrator.TheModulusSetsAHangingSheetsStrain): the top springs
// carry the weight below them, strain = areal density x g x length / modulus, a third more
// at the pinned row (8.3 % and 0.083 % -> about 10.7 % and 0.107 %), a hundredth of the strain
// for a hundred times the modulus. Gauss-Seidel rounds with tethers at the rest length hold
// the top row at its rest length whatever the modulus (the default: docs/cloth.md).
TEST(LineSolve, TheModulusSetsAHangingSheetsStrain) {
    const double soft = hanging_top_strain(20, ClothIntegrator::shipped, nullptr, WarpSolve::lines);
    const double stiff = hanging_top_strain(2000, ClothIntegrator::shipped, nullptr, WarpSolve::lines);
    const double load = 0.17 * double(standard_gravity_m_s2) * 1.0;  // strain x E
    EXPECT_GT(soft, load / 20);
    EXPECT_LT(soft, 1.5 * load / 20);
    EXPECT_NEAR(soft / stiff, 100, 10);
}

}  // namespace
}  // namespace drape
