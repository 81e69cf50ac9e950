// Garment builder and material validation under bounded random input, valid or not: every
// case either builds a garment that steps without ever producing a non-finite value (no
// reset) or is refused with one line naming the field. Deterministic seed, a fixed number
// of small cases.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <limits>
#include <random>
#include <sstream>
#include <string>

#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"
#include "drape/systems/cloth_systems.hpp"
#include "drape/systems/cloth/garment_builder.hpp"

namespace drape {
namespace {

constexpr Real inf = std::numeric_limits<Real>::infinity();
constexpr Real nan = std::numeric_limits<Real>::quiet_NaN();

template <class T, std::size_t N>
T pick(std::mt19937& rng, const std::array<T, N>& values) {
    return values[rng() % N];
}

// A real number that is usually sensible for `typical` and now and then not at all.
Real any_real(std::mt19937& rng, Real typical) {
    const std::array<Real, 12> odd{nan, inf, -inf, 0, -typical, Real(1e-30), Real(1e30), typical * Real(1e-3),
                                   typical * Real(1e3), -0.0f, typical, typical * Real(2)};
    if (rng() % 10 != 0) return typical * std::uniform_real_distribution<Real>(Real(0.5), Real(2))(rng);
    return pick(rng, odd);
}

// The case, for a failure message.
std::string describe(const RectangleParams& p) {
    const ClothMaterial& m = p.material;
    std::ostringstream out;
    out << p.warp_lines << " x " << p.particles_per_line << " stride " << p.weft_stride << ", " << p.width_m << " x "
        << p.length_m << " m, " << (p.model == ClothModel::classic ? "classic" : "simplified")
        << (p.hanging ? ", hanging" : ", lying") << "; density " << m.areal_density_kg_m2 << ", stretch " << m.stretch_N_m
        << ", shear " << m.shear_N_m << ", bend " << m.bend_N_m << ", drag " << m.drag_N_s_m3 << ", friction "
        << m.friction << ", strain_limit " << m.strain_limit << ", iterations " << m.iterations << ", margin "
        << m.candidate_margin_m;
    return out.str();
}

TEST(GarmentBuilderFuzz, RandomRectanglesBuildAndStayFiniteOrGiveOneError) {
    std::mt19937 rng(20071);
    // Grids: small valid ones, invalid ones, and one far above max_garment_particles.
    const std::array<int, 10> lines{-3, 0, 1, 2, 4, 7, 10, 13, 16, 700001};
    const std::array<int, 9> per_line{-1, 0, 1, 2, 3, 8, 16, 30, 700001};
    const std::array<int, 6> strides{-1, 0, 1, 2, 3, 7};
    int built = 0, refused = 0;
    for (int i = 0; i < 300; ++i) {
        RectangleParams p;
        if (rng() % 2 == 0) {  // a valid grid, so that the other fields get tried
            p.warp_lines = pick(rng, std::array<int, 5>{4, 7, 10, 13, 16});
            p.particles_per_line = pick(rng, std::array<int, 4>{2, 8, 16, 30});
            p.weft_stride = 3;
        } else {
            p.warp_lines = pick(rng, lines);
            p.particles_per_line = pick(rng, per_line);
            p.weft_stride = pick(rng, strides);
        }
        p.width_m = any_real(rng, 1);
        p.length_m = any_real(rng, 1);
        p.origin = Vec3(any_real(rng, 1), any_real(rng, 2), any_real(rng, 1));
        p.hanging = rng() % 2 == 0;
        p.model = rng() % 2 ? ClothModel::classic : ClothModel::simplified;
        p.collision = rng() % 2 ? CollisionMode::brute_force : CollisionMode::candidate_lists;
        ClothMaterial& m = p.material;
        m.areal_density_kg_m2 = any_real(rng, Real(0.17));
        m.stretch_N_m = any_real(rng, Real(2000));
        m.shear_N_m = any_real(rng, Real(100));
        m.bend_N_m = any_real(rng, Real(10));
        m.drag_N_s_m3 = any_real(rng, Real(0.3));
        m.friction = any_real(rng, Real(0.4));
        m.strain_limit = any_real(rng, Real(0.1));
        m.iterations = rng() % 10 ? 4 : pick(rng, std::array<int, 4>{-1, 0, 1, 1000000});
        m.candidate_margin_m = any_real(rng, Real(0.08));

        Registry registry;
        auto garment = attach_rectangle(registry, p);
        if (!garment) {
            ++refused;
            const std::string& message = garment.error().message;
            EXPECT_FALSE(message.empty());
            EXPECT_EQ(message.find('\n'), std::string::npos) << message;
            EXPECT_NE(message.find(':'), std::string::npos) << "names no field: " << message;
            continue;
        }
        ++built;
        const Garment& g = registry.get<Garment>(*garment);
        ASSERT_LE(g.state.x.cols(), max_garment_particles);
        ASSERT_TRUE(g.state.x.allFinite());
        Scheduler scheduler;
        add_cloth_systems(scheduler);
        for (int frame = 0; frame < 3; ++frame) ASSERT_TRUE(scheduler.tick(registry, 1.0 / 60.0));
        EXPECT_TRUE(g.state.x.allFinite()) << "case " << i;
        EXPECT_TRUE(g.state.v.allFinite()) << "case " << i;
        // The collision step resets a garment that went non-finite, so finite values alone
        // prove nothing: a material the builder accepted must never produce one.
        EXPECT_EQ(g.counters.non_finite_values, 0u) << "case " << i << ": " << describe(p);
        EXPECT_EQ(g.counters.resets, 0u) << "case " << i << ": " << describe(p);
    }
    RecordProperty("built", built);
    RecordProperty("refused", refused);
    // Both outcomes occur, so neither branch above is dead.
    EXPECT_GT(built, 50);
    EXPECT_GT(refused, 100);
}

}  // namespace
}  // namespace drape
