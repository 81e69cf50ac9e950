// How `drape bench peers` picks Bullet's configuration (on Bullet's figures only), and that
// Bullet's links keep the rest lengths they are given.
#include <gtest/gtest.h>

#include <cmath>

#include "bench/bullet_cloth.hpp"

namespace drape::bench {
namespace {

TEST(BulletSelection, CheapestThatMeetsTheRule) {
    const std::vector<BulletCandidate> c{
        {true, 0.5, 0.30, 0.001},    // cheap, too much strain
        {true, 2.0, 0.08, 0.0015},   // qualifies
        {true, 1.0, 0.09, 0.0019},   // qualifies, cheaper
        {true, 0.8, 0.05, 0.004},    // too deep after the frame
        {false, 0.1, 0.01, 0.0},     // blew up
    };
    const BulletSelection s = select_bullet_configuration(c, {});
    EXPECT_EQ(s.index, 2);
    EXPECT_TRUE(s.qualified);
}

TEST(BulletSelection, LeastStrainWhenNoneQualifies) {
    const std::vector<BulletCandidate> c{
        {true, 0.5, 0.40, 0.001},
        {true, 3.0, 0.20, 0.010},
        {true, 2.0, 0.20, 0.020},    // same strain, cheaper
        {false, 0.1, 0.01, 0.0},
    };
    const BulletSelection s = select_bullet_configuration(c, {});
    EXPECT_EQ(s.index, 2);
    EXPECT_FALSE(s.qualified);
}

TEST(BulletSelection, NoneWhenNothingRan) {
    const std::vector<BulletCandidate> c{{false, 1, 0.01, 0}, {false, 2, NAN, NAN}};
    EXPECT_EQ(select_bullet_configuration(c, {}).index, -1);
    EXPECT_EQ(select_bullet_configuration({}, {}).index, -1);
}

TEST(BulletPeer, LinksKeepTheRestLengthsGivenNotTheDistances) {
    // A 3-particle chain hanging from particle 0, placed at twice its rest length.
    ClothSpec c;
    c.x.resize(3, 3);
    c.x << 0, 0, 0, 2, 1.8f, 1.6f, 0, 0, 0;
    c.springs = {{0, 1}, {1, 2}};
    c.rest_m = {0.1f, 0.1f};
    c.pinned = {0};
    auto cloth = BulletCloth::create(c, {}, BulletTuning{});
    ASSERT_TRUE(cloth) << cloth.error().message;
    Matrix3X pinned(3, 1);
    pinned.col(0) = c.x.col(0);
    for (int frame = 0; frame < 120; ++frame) cloth->step(pinned, {}, 1.0 / 60.0);
    const std::vector<Real> rest = cloth->link_rest_lengths();
    ASSERT_EQ(rest.size(), 2u);
    EXPECT_FLOAT_EQ(rest[0], 0.1f);
    EXPECT_FLOAT_EQ(rest[1], 0.1f);
    // The chain pulled itself together toward its rest lengths (not the 0.2 m it was built at).
    const Matrix3X x = cloth->positions();
    EXPECT_LT((x.col(2) - x.col(0)).norm(), 0.3f);
}

TEST(BulletPeer, RejectsRestLengthsThatDoNotFit) {
    ClothSpec c;
    c.x = Matrix3X::Zero(3, 2);
    c.x(1, 1) = -0.1f;
    c.springs = {{0, 1}};
    c.rest_m = {0.1f, 0.2f};
    auto cloth = BulletCloth::create(c, {}, BulletTuning{});
    ASSERT_FALSE(cloth);
    EXPECT_NE(cloth.error().message.find("rest lengths"), std::string::npos);
    c.rest_m = {-1};
    EXPECT_FALSE(BulletCloth::create(c, {}, BulletTuning{}));
}

}  // namespace
}  // namespace drape::bench
