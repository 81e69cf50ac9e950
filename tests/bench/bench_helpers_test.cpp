// The measuring helpers behind `drape bench`: medians, targets, penetration and strain
// metrics, and the Bullet peer driven like a Drape garment.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "bench/bullet_cloth.hpp"
#include "bench/report.hpp"

namespace drape::bench {
namespace {

TEST(BenchMedian, OddEvenAndEmpty) {
    EXPECT_DOUBLE_EQ(median({3, 1, 2}), 2);
    EXPECT_DOUBLE_EQ(median({4, 1, 3, 2}), 2.5);
    EXPECT_DOUBLE_EQ(median({}), 0);
}

TEST(BenchTarget, SaysMetOrMissedAndByHowMuch) {
    const Target met = upper_bound_target("t", 0.08, 0.1, "ms");
    EXPECT_TRUE(met.met);
    EXPECT_EQ(met.margin, "20 % under");
    const Target missed = upper_bound_target("t", 0.25, 0.1, "ms");
    EXPECT_FALSE(missed.met);
    EXPECT_EQ(missed.margin, "missed by 0.150 ms (2.50x the target)");
    EXPECT_FALSE(upper_bound_target("t", NAN, 0.1, "ms").met);
}

Affine3 ellipsoid(const Vec3& centre, const Vec3& radii) {
    Affine3 t = Affine3::Identity();
    t.translate(centre);
    t.scale(radii);
    return t;
}

TEST(BenchPenetration, DepthAlongTheCentreLineInEllipsoidSpace) {
    const std::vector<Affine3> e{ellipsoid(Vec3(1, 0, 0), Vec3(0.5f, 0.2f, 0.2f))};
    Matrix3X x(3, 3);
    x.col(0) = Vec3(1.3f, 0, 0);     // 0.2 m inside along x (surface at 1.5)
    x.col(1) = Vec3(1, 0.3f, 0);     // outside
    x.col(2) = Vec3(1, -0.15f, 0);   // 0.05 m inside along y
    EXPECT_NEAR(max_penetration_m(x, e), 0.2, 1e-5);
    x.col(0) = Vec3(2, 0, 0);
    EXPECT_NEAR(max_penetration_m(x, e), 0.05, 1e-5);
}

TEST(BenchStrain, LongestSpringOverRest) {
    Matrix3X x(3, 3);
    x << 0, 1, 2.5f, 0, 0, 0, 0, 0, 0;
    const std::vector<std::array<std::uint32_t, 2>> springs{{0, 1}, {1, 2}};
    EXPECT_NEAR(max_strain(x, springs, {1, 1}), 0.5, 1e-6);
    EXPECT_NEAR(max_strain(x, springs, rest_lengths(x, springs)), 0.0, 1e-6);
}

/// A 9 x 9 cloth hanging from its top row, touching nothing.
ClothSpec hanging_cloth() {
    ClothSpec c;
    const int n = 9;
    c.x.resize(3, n * n);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const auto p = static_cast<std::uint32_t>(i * n + j);
            c.x.col(p) = Vec3(0.05f * static_cast<Real>(i), 2 - 0.05f * static_cast<Real>(j), 0);
            if (j + 1 < n) c.springs.push_back({p, p + 1});
            if (i + 1 < n) c.springs.push_back({p, p + static_cast<std::uint32_t>(n)});
            if (j == 0) c.pinned.push_back(p);
        }
    return c;
}

TEST(BulletPeer, PinnedParticlesFollowTheirTargetsExactly) {
    const ClothSpec c = hanging_cloth();
    auto cloth = BulletCloth::create(c, {ellipsoid(Vec3(5, 0, 0), Vec3(0.1f, 0.1f, 0.1f))}, BulletTuning{});
    ASSERT_TRUE(cloth) << cloth.error().message;
    Matrix3X pinned(3, static_cast<Eigen::Index>(c.pinned.size()));
    for (int frame = 0; frame < 60; ++frame) {
        for (std::size_t k = 0; k < c.pinned.size(); ++k)
            pinned.col(static_cast<Eigen::Index>(k)) = c.x.col(c.pinned[k]) + Vec3(0.01f * static_cast<Real>(frame), 0, 0);
        std::vector<Affine3> e{ellipsoid(Vec3(5, 0, 0), Vec3(0.1f, 0.1f, 0.1f))};
        cloth->step(pinned, e, 1.0 / 60.0);
    }
    const Matrix3X x = cloth->positions();
    ASSERT_TRUE(x.allFinite());
    for (std::size_t k = 0; k < c.pinned.size(); ++k)
        EXPECT_TRUE(x.col(c.pinned[k]).isApprox(pinned.col(static_cast<Eigen::Index>(k)), 1e-6f));
    // The free particles hang below the pins.
    EXPECT_LT(x.row(1).minCoeff(), 2 - 0.3f);
}

TEST(BulletPeer, RejectsBadInput) {
    ClothSpec c = hanging_cloth();
    c.springs.push_back({0, 10000});
    auto cloth = BulletCloth::create(c, {}, BulletTuning{});
    ASSERT_FALSE(cloth);
    EXPECT_NE(cloth.error().message.find("spring"), std::string::npos);
}

TEST(BenchReport, WritesOnlyItsOwnFile) {
    const auto dir = std::filesystem::temp_directory_path() / "drape-bench-report-test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    { std::ofstream(dir / "notes.md") << "mine"; }
    BenchOptions options;
    options.name = "unit";
    options.out_dir = dir;
    options.command = "drape bench unit";
    Report report("Unit", options, describe_machine());
    report.table({"a", "b"}, {{"1", "2"}});
    auto path = report.write();
    ASSERT_TRUE(path) << path.error().message;
    EXPECT_EQ(path->filename(), "unit.md");
    std::ifstream notes(dir / "notes.md");
    std::string text;
    std::getline(notes, text);
    EXPECT_EQ(text, "mine");
    std::ifstream in(*path);
    std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(all.find("| a | b |"), std::string::npos);
    EXPECT_NE(all.find("drape bench unit"), std::string::npos);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace drape::bench
