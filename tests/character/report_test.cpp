// What `drape inspect` prints, from the report functions it calls.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "drape/engine/assets/character_import.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/character_report.hpp"
#include "tests/character/test_character_file.hpp"

namespace drape {
namespace {

TEST(CharacterReport, TextAndJsonNameMeshesBonesClipsEllipsoidsCoverageAndHeight) {
    const auto dir = test::temp_dir("report");
    test::write_test_character({}, dir / "column.gltf");
    auto c = import_character(dir / "column.gltf");
    std::filesystem::remove_all(dir);
    ASSERT_TRUE(c) << c.error().message;
    const auto body = fit_character_body(**c);
    ASSERT_TRUE(body) << body.error().message;
    const CoverageReport coverage = rest_pose_coverage(**c, *body);
    const std::string text = character_report_text(**c, *body, coverage);
    for (const char* expected : {"height      2.000 m", "40 vertices", "Bend", "1.000 s", "plays once", "ellipsoids", "coverage"})
        EXPECT_NE(text.find(expected), std::string::npos) << expected << "\n" << text;
    const auto json = nlohmann::json::parse(character_report_json(**c, *body, coverage));
    EXPECT_NEAR(json["height_m"].get<double>(), 2.0, 1e-4);
    EXPECT_EQ(json["vertices"].get<int>(), 40);
    EXPECT_EQ(json["clips"][0]["name"], "Bend");
    EXPECT_NEAR(json["clips"][0]["duration_s"].get<double>(), 1.0, 1e-6);
    EXPECT_EQ(json["clips"][0]["loops"], false);  // "Bend" ends turned 90 degrees from its first pose
    EXPECT_EQ(json["ellipsoids"].size(), body->ellipsoids.size());
    EXPECT_EQ(json["legs"], leg_fit_name(body->legs));  // the leg fit used: tight or bounding
    EXPECT_NE(json["legs"], "automatic");
    EXPECT_GE(json["coverage"]["share"].get<double>(), 0.95);
}

}  // namespace
}  // namespace drape
