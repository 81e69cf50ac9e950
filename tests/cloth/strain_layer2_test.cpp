// Layer-2 strain guarantees of the placement (method §4.2, weft.hpp), checked right after the
// constraint system:
// - every layer-2 warp spring with a free end is at most 1.10 x rest, those hanging from the
//   fitting zone included;
// - every weft segment beside a free layer-2 particle that does not hang from a pinned one is
//   at most max(1.10 x the mean rest of its span, chord / weft_stride), the chord being the
//   layer-1 edge the particle is placed on;
// - the back-off (particles above going back onto their chords) restores the warp bound
//   where no bulge could hold it.
#include <gtest/gtest.h>

#include <limits>

#include "analytic_body.hpp"
#include "systems/cloth/garment_builder.hpp"
#include "systems/cloth/garment_step.hpp"
#include "systems/cloth/substeps.hpp"
#include "systems/cloth/weft.hpp"

namespace drape {
namespace {

// Float rounding: relative, plus positions ~1 m from the origin carry ~1e-7 m of error each.
constexpr Real tolerance = Real(1 + 1e-5);
constexpr Real slack_m = Real(1e-6);
constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();

// Counts of what was checked.
struct Checked {
    std::size_t warp = 0, weft = 0;
};

// Asserts both guarantees on the current positions; adds what it checked to `checked`.
// `below_pins`: also the warp springs hanging from a pinned particle (false for the placement
// alone, without the chord lift before it).
void expect_layer2_bounds(const Garment& g, Real limit, Checked& checked, bool below_pins = true) {
    const Fabric& t = *g.fabric;
    const Real stretch = 1 + limit;
    for (std::size_t s = 0; s < t.warp2.size(); ++s) {
        if (g.state.inv_mass[t.warp2.a[s]] == 0 && (!below_pins || g.state.inv_mass[t.warp2.b[s]] == 0)) continue;
        const Real length = (g.state.x.col(t.warp2.b[s]) - g.state.x.col(t.warp2.a[s])).norm();
        ASSERT_LE(length, stretch * t.warp2.rest_m[s] * tolerance + slack_m) << "layer-2 warp spring " << s;
        ++checked.warp;
    }
    // Placement entry of each layer-2 particle.
    std::vector<std::size_t> entry(t.particle_count(), none);
    for (std::size_t k = 0; k < t.weft_particle.size(); ++k) entry[t.weft_particle[k]] = k;
    for (std::size_t s = 0; s < t.weft.size(); ++s) {
        std::size_t k = none;
        for (const std::uint32_t end : {t.weft.a[s], t.weft.b[s]})
            if (entry[end] != none) k = entry[end];
        if (k == none) continue;  // layer 1 to layer 1 (stride 1)
        const std::uint32_t i = t.weft_particle[k], above = t.weft_above[k];
        if (g.state.inv_mass[i] == 0 || (above != none && g.state.inv_mass[above] == 0)) continue;
        const Real chord = (g.state.x.col(t.weft_right[k]) - g.state.x.col(t.weft_left[k])).norm();
        const Real bound = std::max(stretch * t.weft_rest_m[k], chord / Real(t.weft_stride));
        const Real length = (g.state.x.col(t.weft.b[s]) - g.state.x.col(t.weft.a[s])).norm();
        ASSERT_LE(length, bound * tolerance + slack_m) << "weft segment " << s;
        ++checked.weft;
    }
}

TEST(StrainLayer2, WalkingSkirtHoldsTheWarpAndWeftBoundsAfterTheConstraintSystem) {
    Registry registry;
    test::AnalyticBody body(registry);
    const Entity e = *attach_skirt(registry, body.character, TubeParams::skirt());
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& solver = registry.get<GarmentSolver>(e);
    Checked checked;
    test::step_by_hand(body, registry, g, solver, 150, [&](Garment& garment, GarmentSolver&, const ClothSubstep&, int) {
        expect_layer2_bounds(garment, garment.config.material.strain_limit, checked);
    });
    EXPECT_GT(checked.warp, 50000u);
    EXPECT_GT(checked.weft, 100000u);
}

TEST(StrainLayer2, WalkingDressHoldsTheWarpAndWeftBoundsAfterTheConstraintSystem) {
    Registry registry;
    test::AnalyticBody body(registry);
    const Entity e = *attach_dress(registry, body.character, TubeParams::dress());
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& solver = registry.get<GarmentSolver>(e);
    Checked checked;
    test::step_by_hand(body, registry, g, solver, 40, [&](Garment& garment, GarmentSolver&, const ClothSubstep&, int) {
        expect_layer2_bounds(garment, garment.config.material.strain_limit, checked);
    });
    EXPECT_GT(checked.warp, 200000u);
}

// A 4 x 4 hanging sheet (layer-1 lines 0 and 3, layer-2 lines 1 and 2), rests 0.1 m. Row 0
// is pinned with its layer-2 particles 5 cm in front of their chords; layer 1 hangs straight
// at 1.099 x rest. Row 1 can only reach near the pins with a bulge beyond the weft interval;
// row 2 then has no bulge that holds both its warp spring and its weft segments, so row 1
// must go back onto its chord.
TEST(StrainLayer2, RowsAboveGoBackOntoTheirChordsWhereNoBulgeHoldsTheWarpSpring) {
    RectangleParams params;
    params.warp_lines = 4;
    params.particles_per_line = 4;
    params.width_m = Real(0.3);
    params.length_m = Real(0.3);
    Garment g = *make_rectangle(params);
    const Fabric& t = *g.fabric;
    const Vec3 origin = params.origin;
    const Real drop = Real(0.1099);
    for (std::uint32_t line = 0; line < 4; ++line)
        for (std::uint32_t row = 0; row < 4; ++row) {
            const std::uint32_t i = t.grid[line * 4 + row];
            g.state.x.col(i) = origin + Vec3(Real(0.1) * Real(line), -drop * Real(row), 0);
            if (row == 0 && t.layer[i] == 2) g.state.x(2, i) += Real(0.05);          // pinned, off its chord
            if (row > 0 && t.layer[i] == 2) g.state.x(2, i) += Real(0.04);           // wants to follow
        }
    g.state.v.setZero();
    GarmentSolver solver;
    prepare_solver(g, solver);
    compute_layer1_normals(t, g.state.x, solver.normals);
    place_weft(t, solver.normals, g.state.inv_mass, g.state.x, g.state.v, solver.plane_normal, Real(0.01), Real(0.10));

    Checked checked;
    expect_layer2_bounds(g, Real(0.10), checked, false);
    EXPECT_EQ(checked.warp, 4u);  // rows 1 -> 2 and 2 -> 3 on both layer-2 lines
    for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
        const std::uint32_t i = t.weft_particle[k];
        if (g.state.inv_mass[i] == 0) continue;
        EXPECT_NEAR(weft_plane_distance(t, solver.normals, g.state.x, k), 0, 1e-6) << "entry " << k;
        if (k % 4 == 1) {  // row 1: back on its chord
            const Vec3 chord = (1 - t.weft_t[k]) * g.state.x.col(t.weft_left[k]) + t.weft_t[k] * g.state.x.col(t.weft_right[k]);
            EXPECT_LT((g.state.x.col(i) - chord).norm(), 1e-6) << "entry " << k;
        }
    }
}

// Under the fitting zone the pinned layer-2 particles sit off their chords (the waist curves
// around the body): with layer 1 hanging at its limit, the chord below lies farther than the
// limit from them. Lifting the chord's layer-1 ends toward the pinned particle brings every
// hanging particle's chord point within the limit, so the back-off can hold that spring too,
// while the layer-1 warp springs from the pinned row stay within theirs.
TEST(StrainLayer2, ChordsBelowThePinsAreLiftedWithinTheLimitOfThePinnedParticles) {
    RectangleParams params;
    params.warp_lines = 4;
    params.particles_per_line = 4;
    params.width_m = Real(0.3);
    params.length_m = Real(0.3);
    Garment g = *make_rectangle(params);
    const Fabric& t = *g.fabric;
    for (std::uint32_t line = 0; line < 4; ++line)
        for (std::uint32_t row = 0; row < 4; ++row) {
            const std::uint32_t i = t.grid[line * 4 + row];
            g.state.x.col(i) = params.origin + Vec3(Real(0.1) * Real(line), Real(-0.1099) * Real(row), 0);
            if (row == 0 && t.layer[i] == 2) g.state.x(2, i) += Real(0.05);  // pinned, off its chord
        }
    g.state.v.setZero();
    GarmentSolver solver;
    prepare_solver(g, solver);
    const Matrix3X before = g.state.x;
    EXPECT_TRUE(lift_chords_below_pins(t, g.state.inv_mass, g.state.x, g.state.v, solver.force, Real(0.01), Real(0.10)));
    for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
        if (k % 4 != 1) continue;  // row 1 hangs from the pinned row 0
        const Vec3 chord = (1 - t.weft_t[k]) * g.state.x.col(t.weft_left[k]) + t.weft_t[k] * g.state.x.col(t.weft_right[k]);
        EXPECT_LE((chord - g.state.x.col(t.weft_above[k])).norm(), Real(1.10) * t.weft_above_rest_m[k] * tolerance) << "entry " << k;
    }
    for (std::size_t s = 0; s < t.warp1.size(); ++s) {
        const Real length = (g.state.x.col(t.warp1.b[s]) - g.state.x.col(t.warp1.a[s])).norm();
        if (g.state.inv_mass[t.warp1.a[s]] == 0) {
            EXPECT_LE(length, Real(1.10) * t.warp1.rest_m[s] * tolerance) << "spring " << s;
        }
    }
    // Only the layer-1 particles of row 1 moved, and their velocities followed (h = 0.01 s).
    for (Eigen::Index i = 0; i < g.state.x.cols(); ++i) {
        const Vec3 move = g.state.x.col(i) - before.col(i);
        const bool row1_layer1 = t.layer[static_cast<std::size_t>(i)] == 1 && (t.grid[1] == i || t.grid[3 * 4 + 1] == i);
        if (!row1_layer1) EXPECT_EQ(move.norm(), 0) << "particle " << i;
        else EXPECT_LT((g.state.v.col(i) - move / Real(0.01)).norm(), 1e-3) << "particle " << i;
    }
}

// The whole constraint system under a pinned row that curves away from its chords both ways
// (7 lines: layer-1 lines 0, 3, 6; the pinned layer-2 particles of the first span 15 cm in
// front of their chord, those of the second 15 cm behind, rests 0.1 m), layer 1 hanging
// straight at 1.099 x rest: the middle layer-1 line is pulled both ways, and a lift that
// only follows the larger request leaves a chord out of reach. Afterwards every warp spring
// with a free end is within 1.10 x rest, the layer-1 springs from the pins included, and
// every free layer-2 particle lies on its plane. (At 20 cm both ways no placement exists:
// the middle line cannot be within reach of both spans.)
TEST(StrainLayer2, EveryWarpSpringBelowACurvedPinnedRowIsWithinTheLimitAfterTheConstraintSystem) {
    RectangleParams params;
    params.warp_lines = 7;
    params.particles_per_line = 5;
    params.width_m = Real(0.6);
    params.length_m = Real(0.4);
    Garment g = *make_rectangle(params);
    const Fabric& t = *g.fabric;
    const Real offset = Real(0.15);
    for (std::uint32_t line = 0; line < 7; ++line)
        for (std::uint32_t row = 0; row < 5; ++row) {
            const std::uint32_t i = t.grid[line * 5 + row];
            g.state.x.col(i) = params.origin + Vec3(Real(0.1) * Real(line), Real(-0.1099) * Real(row), 0);
            if (row == 0 && t.layer[i] == 2) g.state.x(2, i) += line < 3 ? offset : -offset;
        }
    g.state.v.setZero();
    GarmentSolver solver;
    constrain_garment(g, solver, make_substep(0, 1, 1.0 / 60.0));

    std::size_t below_pins = 0;
    for (const SpringPhase* warp : {&t.warp1, &t.warp2})
        for (std::size_t s = 0; s < warp->size(); ++s) {
            const bool pinned_a = g.state.inv_mass[warp->a[s]] == 0;
            if (pinned_a && g.state.inv_mass[warp->b[s]] == 0) continue;
            const Real length = (g.state.x.col(warp->b[s]) - g.state.x.col(warp->a[s])).norm();
            EXPECT_LE(length, Real(1.10) * warp->rest_m[s] * tolerance + slack_m) << "warp spring " << s;
            below_pins += pinned_a ? 1 : 0;
        }
    EXPECT_EQ(below_pins, 7u);  // every line's first spring
    compute_layer1_normals(t, g.state.x, solver.normals);
    for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
        if (g.state.inv_mass[t.weft_particle[k]] == 0) continue;
        EXPECT_NEAR(weft_plane_distance(t, solver.normals, g.state.x, k), 0, 1e-6) << "entry " << k;
    }
}

}  // namespace
}  // namespace drape
