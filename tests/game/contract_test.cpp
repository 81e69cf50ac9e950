// The verdict `drape play` prints on every garment: the contract's limits, what broke,
// and the names of the garments in a scene.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "drape/game/contract.hpp"

namespace drape {
namespace {

GarmentStats good() {
    GarmentStats s;
    s.strain_p99 = 0.051;
    s.strain_max = 0.092;
    s.penetration_after_frame_m = 0;
    s.rise_above_pins_m = 0.01;
    return s;
}

TEST(Contract, AGarmentWithinTheLimitsGetsOneLineSayingSo) {
    EXPECT_TRUE(contract_breaches(good()).empty());
    EXPECT_EQ(garment_verdict("skirt", good()), "skirt: strain p99 5.1 %, max 9.2 %, penetration 0.0 mm: within the contract");
}

TEST(Contract, TheLimitsThemselvesAreWithinTheContract) {
    GarmentStats s;
    s.strain_p99 = 0.10;
    s.strain_max = 0.20;
    s.penetration_after_frame_m = 0.002;
    s.rise_above_pins_m = 0.15;
    EXPECT_TRUE(contract_breaches(s).empty());
}

TEST(Contract, EveryBreachIsNamedWithItsFigureAndLimit) {
    GarmentStats s = good();
    s.strain_p99 = 0.125;
    EXPECT_EQ(contract_breaches(s), std::vector<std::string>{"strain p99 12.5 % > 10 %"});
    s = good();
    s.strain_max = 0.314;
    EXPECT_EQ(garment_verdict("dress", s),
              "dress: strain p99 5.1 %, max 31.4 %, penetration 0.0 mm: outside the contract: strain max 31.4 % > 20 %");
    s = good();
    s.penetration_after_frame_m = 0.0035;
    EXPECT_EQ(contract_breaches(s), std::vector<std::string>{"penetration after the frame 3.5 mm > 2 mm"});
    s = good();
    s.rise_above_pins_m = 0.2;
    EXPECT_EQ(contract_breaches(s), std::vector<std::string>{"rise above the pins 20.0 cm > 15 cm"});
    s = good();
    s.nonfinite = 3;
    EXPECT_EQ(contract_breaches(s), std::vector<std::string>{"3 non-finite value(s)"});
    s = good();
    s.compression_min = 0.013;
    EXPECT_EQ(contract_breaches(s), std::vector<std::string>{"shortest spring 1.3 % of its rest length < 25 %"});
    s.compression_min = 0.25;
    EXPECT_TRUE(contract_breaches(s).empty());
    s = good();
    s.below_ground_m = 0.004;
    EXPECT_EQ(contract_breaches(s), std::vector<std::string>{"below the floor 4.0 mm > 2 mm"});
}

TEST(Contract, SeveralBreachesAreAllNamedAndANaNFigureIsABreach) {
    GarmentStats s = good();
    s.strain_max = std::numeric_limits<double>::quiet_NaN();
    s.penetration_after_frame_m = 0.01;
    const auto breaches = contract_breaches(s);
    ASSERT_EQ(breaches.size(), 2u);
    EXPECT_EQ(breaches[0], "strain max nan % > 20 %");
    EXPECT_EQ(breaches[1], "penetration after the frame 10.0 mm > 2 mm");
    EXPECT_NE(garment_verdict("skirt", s).find("outside the contract: strain max nan % > 20 %, penetration after"),
              std::string::npos);
}

TEST(Contract, GarmentsAreNamedByTypeAndWithSeveralByIndexAndCharacter) {
    SceneDescription scene;
    scene.characters.resize(2);
    scene.characters[0].file = "assets/avatar.glb";
    scene.characters[1].file = "x/Male_Casual.fbx";
    scene.garments.resize(1);
    EXPECT_EQ(garment_names(scene), std::vector<std::string>{"skirt"});
    scene.garments.resize(2);
    scene.garments[1].type = GarmentType::dress;
    scene.garments[1].character = 1;
    EXPECT_EQ(garment_names(scene), (std::vector<std::string>{"garments[0] skirt on avatar", "garments[1] dress on Male_Casual"}));
}

}  // namespace
}  // namespace drape
