// Provot strain limiting and layer-2 placement (method §4.1, §4.2), checked right after the
// constraint system on a skirt worn by a walking analytic body, for both models.
#include <gtest/gtest.h>

#include "analytic_body.hpp"
#include "systems/cloth/garment_builder.hpp"
#include "systems/cloth/garment_step.hpp"
#include "systems/cloth/strain_limit.hpp"
#include "systems/cloth/substeps.hpp"
#include "systems/cloth/weft.hpp"

namespace drape {
namespace {

// Asserts that every warp spring with at least one free end is within 1.10 x rest (between
// two pinned particles the skin decides); returns how many layer-2 warp springs hanging from
// a pinned particle it checked.
std::size_t expect_warp_within_limit(const Garment& g) {
    const Fabric& t = *g.fabric;
    std::size_t below_pins = 0;
    for (const SpringPhase* warp : {&t.warp1, &t.warp2}) {
        for (std::size_t s = 0; s < warp->size(); ++s) {
            const bool pinned_a = g.state.inv_mass[warp->a[s]] == 0, pinned_b = g.state.inv_mass[warp->b[s]] == 0;
            if (pinned_a && pinned_b) continue;
            const Real length = (g.state.x.col(warp->b[s]) - g.state.x.col(warp->a[s])).norm();
            EXPECT_LE(length, Real(1.10) * warp->rest_m[s] * Real(1 + 1e-5) + Real(1e-6))
                << (warp == &t.warp1 ? "layer-1" : "layer-2") << " warp spring " << s << (pinned_a ? " below a pin" : "");
            if (length > Real(1.10) * warp->rest_m[s] * Real(1 + 1e-5) + Real(1e-6)) return below_pins;
            if (warp == &t.warp2 && pinned_a) ++below_pins;
        }
    }
    return below_pins;
}

class ConstraintOnWalkingSkirt : public ::testing::TestWithParam<ClothModel> {};

// Classic: Provot on every warp spring (§4.1). Simplified: Provot on the layer-1 warp, the
// layer-2 warp through the placement (§4.2, weft.hpp), the springs hanging from the fitting
// zone included: the chords below it are lifted within reach of the pinned particles.
TEST_P(ConstraintOnWalkingSkirt, NoWarpSpringLongerThanTenPercentAfterTheConstraintSystem) {
    Registry registry;
    test::AnalyticBody body(registry);
    TubeParams params = TubeParams::skirt();
    params.model = GetParam();
    const Entity e = *attach_skirt(registry, body.character, params);
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& solver = registry.get<GarmentSolver>(e);
    int checks = 0;
    std::size_t below_pins = 0;
    test::step_by_hand(body, registry, g, solver, 120, [&](Garment& garment, GarmentSolver&, const ClothSubstep&, int) {
        if (::testing::Test::HasFailure()) return;
        below_pins += expect_warp_within_limit(garment);
        ++checks;
    });
    EXPECT_GT(checks, 100);
    if (GetParam() == ClothModel::simplified) {
        EXPECT_GT(below_pins, 1000u);
    }
}

TEST_P(ConstraintOnWalkingSkirt, NoWarpSpringOfAWalkingDressLongerThanTenPercentAfterTheConstraintSystem) {
    Registry registry;
    test::AnalyticBody body(registry);
    TubeParams params = TubeParams::dress();
    params.model = GetParam();
    const Entity e = *attach_dress(registry, body.character, params);
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& solver = registry.get<GarmentSolver>(e);
    int checks = 0;
    std::size_t below_pins = 0;
    const bool simplified = GetParam() == ClothModel::simplified;
    const Fabric& t = *g.fabric;
    Matrix3X normals(3, t.layer1_count);
    std::size_t on_planes = 0;
    test::step_by_hand(body, registry, g, solver, simplified ? 120 : 60, [&](Garment& garment, GarmentSolver&, const ClothSubstep&, int) {
        if (::testing::Test::HasFailure()) return;
        below_pins += expect_warp_within_limit(garment);
        ++checks;
        if (!simplified) return;
        compute_layer1_normals(t, garment.state.x, normals);
        for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
            if (garment.state.inv_mass[t.weft_particle[k]] == 0) continue;
            ASSERT_NEAR(weft_plane_distance(t, normals, garment.state.x, k), 0, 1e-5) << "layer-2 entry " << k;
            ++on_planes;
        }
    });
    EXPECT_GT(checks, 59);
    if (simplified) {
        EXPECT_GT(below_pins, 1000u);
        EXPECT_GT(on_planes, 100000u);
    }
}

TEST_P(ConstraintOnWalkingSkirt, PinnedParticlesAreNeverMovedByTheConstraints) {
    Registry registry;
    test::AnalyticBody body(registry);
    TubeParams params = TubeParams::skirt();
    params.model = GetParam();
    const Entity e = *attach_skirt(registry, body.character, params);
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& solver = registry.get<GarmentSolver>(e);
    test::step_by_hand(body, registry, g, solver, 30, [&](Garment& garment, GarmentSolver& s, const ClothSubstep& ctx, int) {
        if (!ctx.last()) return;  // mid-step pins are between two targets
        for (Eigen::Index i = 0; i < s.pin_target.cols(); ++i)
            ASSERT_EQ(garment.state.x.col(garment.state.pins[static_cast<std::size_t>(i)].particle), s.pin_target.col(i));
    });
}

INSTANTIATE_TEST_SUITE_P(Models, ConstraintOnWalkingSkirt,
                         ::testing::Values(ClothModel::simplified, ClothModel::classic),
                         [](const auto& info) { return info.param == ClothModel::simplified ? "simplified" : "classic"; });

TEST(Weft, LayerTwoParticlesLieOnTheirPlanesAfterTheConstraintSystem) {
    Registry registry;
    test::AnalyticBody body(registry);
    const Entity e = *attach_skirt(registry, body.character, TubeParams::skirt());
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& solver = registry.get<GarmentSolver>(e);
    const Fabric& t = *g.fabric;
    Matrix3X normals(3, t.layer1_count);
    std::size_t checked = 0;
    test::step_by_hand(body, registry, g, solver, 90, [&](Garment& garment, GarmentSolver&, const ClothSubstep&, int) {
        compute_layer1_normals(t, garment.state.x, normals);
        for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
            if (garment.state.inv_mass[t.weft_particle[k]] == 0) continue;
            ASSERT_NEAR(weft_plane_distance(t, normals, garment.state.x, k), 0, 1e-5) << "layer-2 entry " << k;
            ++checked;
        }
    });
    EXPECT_GT(checked, 1000u);
}

TEST(Weft, VelocityIsTheNeighboursVelocityProjectedOntoThePlane) {
    const Garment g0 = *make_rectangle(RectangleParams{});
    Garment g = g0;
    const Fabric& t = *g.fabric;
    // Give layer 1 a shear-free but non-uniform motion and move layer 1 off the flat sheet.
    Matrix3X& x = g.state.x;
    for (Eigen::Index i = 0; i < static_cast<Eigen::Index>(t.layer1_count); ++i) {
        g.state.v.col(i) = Vec3(Real(0.1) * x(0, i), Real(-0.3), Real(0.2) * x(1, i));
        x(2, i) += Real(0.05) * std::sin(Real(3) * x(0, i));
    }
    GarmentSolver s;
    prepare_solver(g, s);
    compute_layer1_normals(t, x, s.normals);
    place_weft(t, s.normals, g.state.inv_mass, x, g.state.v, s.plane_normal, Real(0.01));
    for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
        const std::uint32_t i = t.weft_particle[k];
        if (g.state.inv_mass[i] == 0) continue;
        const Vec3 p = s.plane_normal.col(i);
        const Vec3 blend = (1 - t.weft_t[k]) * g.state.v.col(t.weft_left[k]) + t.weft_t[k] * g.state.v.col(t.weft_right[k]);
        EXPECT_NEAR(p.norm(), 1, 1e-5);
        EXPECT_NEAR(g.state.v.col(i).dot(p), 0, 1e-6);
        EXPECT_LT((g.state.v.col(i) - (blend - blend.dot(p) * p)).norm(), 1e-6);
    }
}

TEST(StrainLimit, OrderedPassBoundsAChainExactlyFromItsPinnedEnd) {
    // A chain stretched to 3x its rest length, pinned at the top.
    SpringPhase chain;
    const int n = 20;
    Matrix3X x(3, n), v = Matrix3X::Zero(3, n);
    for (int i = 0; i < n; ++i) x.col(i) = Vec3(0, -3 * Real(i), 0);
    for (int i = 0; i + 1 < n; ++i) chain.add(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i + 1), 1);
    std::vector<std::uint8_t> movable(n, 1);
    movable[0] = 0;
    StrainLimitOptions options;
    options.h_s = Real(0.01);
    limit_strain(chain, x, v, movable, options);
    EXPECT_EQ(x.col(0), Vec3::Zero());
    EXPECT_LE(max_strain(chain, x), Real(0.10) + Real(1e-5));
    // Velocities follow the moves: the last particle moved up by 57 - 1.1 * 19 m in 0.01 s.
    EXPECT_NEAR(v(1, n - 1), (3 * 19 - 1.1 * 19) / 0.01, 1e-1);
}

}  // namespace
}  // namespace drape
