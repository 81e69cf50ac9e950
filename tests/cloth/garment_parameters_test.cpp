// The garment parameter table: names are unique, the skirt's and the dress's defaults lie in
// every range, validate() walks the table for tubes and for materials, and bounds print as
// people write them.
#include <gtest/gtest.h>

#include <limits>
#include <set>
#include <string>

#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_parameters.hpp"

namespace drape {
namespace {

TEST(GarmentParameterTable, NamesAreUniqueAndFoundByName) {
    std::set<std::string_view> names;
    for (const GarmentParameterSpec& spec : garment_parameters()) {
        EXPECT_TRUE(names.insert(spec.name).second) << spec.name;
        EXPECT_EQ(find_garment_parameter(spec.name), &spec);
        EXPECT_FALSE(spec.description.empty()) << spec.name;
        EXPECT_LT(spec.range.min, spec.range.max) << spec.name;
    }
    EXPECT_EQ(find_garment_parameter("waist_height_m"), nullptr);
    // Every ClothMaterial field a garment carries is a row (14 of them, weft bending and the
    // limits' share included), and so is every
    // numeric field of TubeParams (20, the inertia scales with their acceleration and fall
    // bounds, the max distance and its centres on the skin, the hem clearance, the line
    // spacing and the thin trunk pieces included).
    int material = 0;
    for (const GarmentParameterSpec& spec : garment_parameters()) material += spec.in_material();
    EXPECT_EQ(material, 14);
    EXPECT_EQ(garment_parameters().size(), 34u);
}

TEST(MaterialPresets, AreValidDistinctAndFoundByName) {
    ASSERT_GE(material_presets().size(), 3u);
    for (const MaterialPreset& preset : material_presets()) {
        EXPECT_TRUE(validate(preset.material, "material")) << preset.name;
        auto found = material_preset(preset.name);
        ASSERT_TRUE(found) << preset.name;
        EXPECT_EQ(*found, preset.material);
    }
    EXPECT_EQ(*material_preset("cotton"), ClothMaterial{});  // the default cloth
    EXPECT_LT(material_preset("silk")->areal_density_kg_m2, material_preset("denim")->areal_density_kg_m2);
    EXPECT_LT(material_preset("silk")->stretch_N_m, material_preset("denim")->stretch_N_m);
    const auto missing = material_preset("tweed");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().message, "material \"tweed\": no such preset (presets: silk, cotton, denim)");
}

TEST(GarmentParameterTable, SkirtAndDressDefaultsAreValid) {
    for (const TubeParams& params : {TubeParams::skirt(), TubeParams::dress()})
        for (const GarmentParameterSpec& spec : garment_parameters())
            EXPECT_TRUE(spec.range.contains(spec.get(params))) << spec.name << " = " << spec.get(params);
    EXPECT_TRUE(validate(TubeParams::skirt(), "skirt"));
    EXPECT_TRUE(validate(TubeParams::dress(), "dress"));
    EXPECT_EQ(TubeParams::skirt().warp_lines * TubeParams::skirt().particles_per_line, 837);
    EXPECT_EQ(TubeParams::dress().warp_lines * TubeParams::dress().particles_per_line, 10080);
}

TEST(GarmentParameterTable, ValidateNamesTheRowAndItsRange) {
    TubeParams p = TubeParams::skirt();
    find_garment_parameter("candidate_margin_m")->set(p, 0);
    auto r = validate(p, "skirt");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message, "skirt.material.candidate_margin_m: must be in (0, 1] m, got 0");
    p = TubeParams::dress();
    find_garment_parameter("ring_height_fraction")->set(p, 1);
    r = validate(p, "dress");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message, "dress.ring_height_fraction: must be in [0, 1), got 1");
    p = TubeParams::skirt();
    find_garment_parameter("iterations")->set(p, 1e6);
    EXPECT_EQ(validate(p, "skirt").error().message, "skirt.material.iterations: must be in [1, 100], got 1000000");
    // A material alone (a rectangle's, a running garment's) is checked by the same rows.
    ClothMaterial m;
    m.shear_N_m = -1;
    EXPECT_EQ(validate(m, "rectangle.material").error().message, "rectangle.material.shear_N_m: must be in [0, 1e7] N/m, got -1");
    m = {};
    m.drag_N_s_m3 = std::numeric_limits<Real>::infinity();
    EXPECT_EQ(validate(m, "material").error().message, "material.drag_N_s_m3: must be in [0, 100] N s/m^3, got inf");
}

TEST(GarmentParameterTable, SetRoundsIntegersAndGetReadsBack) {
    TubeParams p;
    const GarmentParameterSpec& lines = *find_garment_parameter("warp_lines");
    lines.set(p, 29.6);
    EXPECT_EQ(p.warp_lines, 30);
    EXPECT_EQ(lines.get(p), 30);
    const GarmentParameterSpec& density = *find_garment_parameter("areal_density_kg_m2");
    density.set(p, 0.5);
    EXPECT_EQ(p.material.areal_density_kg_m2, Real(0.5));
    EXPECT_EQ(density.get(p.material), 0.5);
    EXPECT_EQ(density.field(), "material.areal_density_kg_m2");
    EXPECT_EQ(lines.field(), "warp_lines");
}

TEST(ParameterNumberText, WritesNumbersAsPeopleDo) {
    EXPECT_EQ(parameter_number_text(0), "0");
    EXPECT_EQ(parameter_number_text(250000), "250000");
    EXPECT_EQ(parameter_number_text(1e7), "1e7");
    EXPECT_EQ(parameter_number_text(0.3), "0.3");
    EXPECT_EQ(parameter_number_text(double(Real(0.55))), "0.55");
    EXPECT_EQ(parameter_number_text(double(Real(0.00018))), "0.00018");
    EXPECT_EQ(parameter_number_text(1.5e-5), "1.5e-5");
    EXPECT_EQ(parameter_number_text(-2), "-2");
    EXPECT_EQ((ParameterRange{0, 10, true, false}.text()), "(0, 10]");
    EXPECT_EQ((ParameterRange{0, 1, true, true}.text()), "(0, 1)");
}

TEST(ParameterRange, EndsAreOpenOrClosedAndNanIsOutside) {
    const ParameterRange r{0, 1, true, false};
    EXPECT_FALSE(r.contains(0));
    EXPECT_TRUE(r.contains(1e-30));
    EXPECT_TRUE(r.contains(1));
    EXPECT_FALSE(r.contains(1.0000001));
    EXPECT_FALSE(r.contains(std::numeric_limits<double>::quiet_NaN()));
    EXPECT_FALSE(r.contains(std::numeric_limits<double>::infinity()));
    const ParameterRange closed{0, 1, false, false};
    EXPECT_TRUE(closed.contains(0));
    EXPECT_FALSE(closed.contains(-1e-300));
}

}  // namespace
}  // namespace drape
