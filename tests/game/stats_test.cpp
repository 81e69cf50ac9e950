// The --stats file: exactly the documented fields, written atomically.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "drape/components/garment.hpp"
#include "drape/game/stats.hpp"
#include "drape/systems/cloth/garment_builder.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

// A rectangle of 4 lines of 4 particles, pinned at its top, hanging in the air.
Entity attach_small_rectangle(Registry& registry) {
    RectangleParams params;
    params.warp_lines = 4;
    params.particles_per_line = 4;
    return *attach_rectangle(registry, params);
}

std::vector<std::string> keys(const nlohmann::json& j) {
    std::vector<std::string> out;
    for (const auto& [k, v] : j.items()) out.push_back(k);
    std::sort(out.begin(), out.end());
    return out;
}

RunStats example() {
    RunStats r;
    r.frames = 240;
    r.sim_dt_s = 1.0 / 60.0;
    SystemStats s;
    s.name = "cloth_integrate";
    s.runs = 480;
    s.skips = 2;
    s.mean_ms = 0.25;
    s.p50_ms = 0.2;
    s.p95_ms = 0.5;
    s.max_ms = 1.5;
    r.systems.push_back(s);
    s.name = "render";
    s.mean_ms = std::numeric_limits<double>::quiet_NaN();  // must not produce invalid JSON
    r.systems.push_back(s);
    r.characters.push_back({.file = "assets/avatar.glb", .clip = "Walk", .height_m = 1.75});
    r.garments.push_back({.particles = 837, .strain_max = 0.1, .strain_p99 = 0.05, .penetration_after_frame_m = 0.0001,
                          .within_give_m = 0.02, .penetration_before_response_m = 0.004, .pins_inside_m = 0.002, .below_ground_m = 0.003, .rise_above_pins_m = 0.01,
                          .nonfinite = 0, .resets = 1, .collision_tests_per_frame = 1234.5});
    r.garments.back().compression_min = 0.8;
    r.garments.back().pinned_strain_max = 0.3;
    r.garments.back().repair_rounds_max = 7;
    r.garments.back().budget_hits = 3;
    r.garments.back().substeps_mean = 1.5;
    r.garments.back().substeps_max = 4;
    r.garments.back().line_steps_per_frame = 27.5;
    r.garments.back().skin_measured = true;
    r.garments.back().skin_penetration_p99_m = 0.004;
    r.garments.back().skin_penetration_max_m = 0.006;
    r.garments.back().skin_penetration_share = 0.01;
    r.garments.back().speed_max_m_s = 12.5;
    r.garments.back().worst_spring = {.seen = true, .frame = 12, .weft = true, .line = 58, .row = 26, .rows = 84,
                                      .body_part = "torso", .part_thickness_m = 0.01, .straddles = true};
    return r;
}

TEST(StatsFile, HasExactlyTheDocumentedFields) {
    const nlohmann::json j = nlohmann::json::parse(stats_json(example()));
    EXPECT_EQ(keys(j), (std::vector<std::string>{"characters", "frames", "garments", "sim_dt_s", "systems"}));
    ASSERT_EQ(j["characters"].size(), 1u);
    EXPECT_EQ(keys(j["characters"][0]), (std::vector<std::string>{"clip", "file", "height_m"}));
    EXPECT_EQ(j["characters"][0]["clip"], "Walk");
    EXPECT_EQ(j["frames"], 240);
    EXPECT_DOUBLE_EQ(j["sim_dt_s"].get<double>(), 1.0 / 60.0);
    ASSERT_TRUE(j["systems"].is_object());
    EXPECT_EQ(keys(j["systems"]), (std::vector<std::string>{"cloth_integrate", "render"}));
    const auto& cloth = j["systems"]["cloth_integrate"];
    EXPECT_EQ(keys(cloth), (std::vector<std::string>{"max_ms", "mean_ms", "p50_ms", "p95_ms", "runs", "skips"}));
    EXPECT_EQ(cloth["runs"], 480);
    EXPECT_EQ(cloth["skips"], 2);
    EXPECT_DOUBLE_EQ(cloth["p95_ms"].get<double>(), 0.5);
    EXPECT_TRUE(j["systems"]["render"]["mean_ms"].is_null());
    ASSERT_TRUE(j["garments"].is_array());
    ASSERT_EQ(j["garments"].size(), 1u);
    const auto& g = j["garments"][0];
    EXPECT_EQ(keys(g), (std::vector<std::string>{"budget_hits", "collision_tests_per_frame", "compression_min",
                                                 "line_steps_per_frame", "max_penetration_m", "max_strain", "nonfinite",
                                                 "particles", "penetration_m",
                                                 "pins_inside_m", "repair_rounds_max", "resets", "rise_above_pins_m",
                                                 "skin_penetration_m", "speed_max_m_s", "strain", "substeps_max", "substeps_mean"}));
    EXPECT_DOUBLE_EQ(g["speed_max_m_s"].get<double>(), 12.5);
    EXPECT_DOUBLE_EQ(g["compression_min"].get<double>(), 0.8);
    EXPECT_DOUBLE_EQ(g["substeps_mean"].get<double>(), 1.5);
    EXPECT_EQ(g["substeps_max"], 4);
    EXPECT_EQ(g["repair_rounds_max"], 7);
    EXPECT_EQ(g["budget_hits"], 3);
    EXPECT_DOUBLE_EQ(g["line_steps_per_frame"].get<double>(), 27.5);
    EXPECT_EQ(keys(g["strain"]), (std::vector<std::string>{"max", "p99", "pinned_max", "worst"}));
    const auto& worst = g["strain"]["worst"];
    EXPECT_EQ(keys(worst), (std::vector<std::string>{"body_part", "frame", "line", "part_thickness_m", "row", "rows",
                                                     "spring", "straddles"}));
    EXPECT_EQ(worst["frame"], 12);
    EXPECT_EQ(worst["spring"], "weft");
    EXPECT_EQ(worst["line"], 58);
    EXPECT_EQ(worst["row"], 26);
    EXPECT_EQ(worst["rows"], 84);
    EXPECT_EQ(worst["body_part"], "torso");
    EXPECT_DOUBLE_EQ(worst["part_thickness_m"].get<double>(), 0.01);
    EXPECT_EQ(worst["straddles"], true);
    EXPECT_DOUBLE_EQ(g["strain"]["pinned_max"].get<double>(), 0.3);
    EXPECT_EQ(keys(g["penetration_m"]), (std::vector<std::string>{"after_frame_max", "before_response_max", "below_ground_max", "within_give_max"}));
    EXPECT_DOUBLE_EQ(g["strain"]["p99"].get<double>(), 0.05);
    EXPECT_DOUBLE_EQ(g["penetration_m"]["before_response_max"].get<double>(), 0.004);
    EXPECT_DOUBLE_EQ(g["penetration_m"]["within_give_max"].get<double>(), 0.02);
    EXPECT_DOUBLE_EQ(g["penetration_m"]["below_ground_max"].get<double>(), 0.003);
    EXPECT_EQ(keys(g["skin_penetration_m"]), (std::vector<std::string>{"max", "p99", "share"}));
    EXPECT_DOUBLE_EQ(g["skin_penetration_m"]["p99"].get<double>(), 0.004);
    EXPECT_DOUBLE_EQ(g["skin_penetration_m"]["max"].get<double>(), 0.006);
    EXPECT_DOUBLE_EQ(g["skin_penetration_m"]["share"].get<double>(), 0.01);
    EXPECT_EQ(g["resets"], 1);
    EXPECT_EQ(g["particles"], 837);
    EXPECT_DOUBLE_EQ(g["collision_tests_per_frame"].get<double>(), 1234.5);
}

TEST(StatsFile, IsWrittenWholeOrNotAtAll) {
    const fs::path dir = fs::temp_directory_path() / ("drape_stats_test_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path file = dir / "stats.json";
    ASSERT_TRUE(write_stats(example(), file));
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), stats_json(example()));
    EXPECT_FALSE(fs::exists(dir / "stats.json.partial"));

    auto missing = write_stats(example(), dir / "no" / "stats.json");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().message, (dir / "no" / "stats.json").string() + ": folder " + (dir / "no").string() + " does not exist");
    auto folder = write_stats(example(), dir);
    ASSERT_FALSE(folder);
    EXPECT_EQ(folder.error().message, dir.string() + ": is a folder");
    fs::remove_all(dir);
}

TEST(GarmentWatch, ReportsWorstValuesAfterEachFrameAndNonFiniteParticles) {
    Registry registry;
    const Entity e = attach_small_rectangle(registry);
    Garment& g = registry.get<Garment>(e);
    g.counters.collision_tests = 100;  // before the run: not counted
    GarmentWatch watch(registry, {e});

    // Frame 1: the hem row 20 % longer along the warp than at rest; the collision found a 1 cm push.
    const Fabric& t = *g.fabric;
    const std::uint32_t hem = t.grid[3], above = t.grid[2];  // line 0, rows 3 and 2
    const Real rest = (g.state.x.col(hem) - g.state.x.col(above)).norm();
    g.state.x.col(hem) = g.state.x.col(above) + (g.state.x.col(hem) - g.state.x.col(above)) * Real(1.2);
    g.counters.max_penetration_m = 0.01f;
    g.counters.substeps = 3;
    watch.sample(registry);
    // Frame 2: back to rest, fewer found, a NaN, one substep.
    g.state.x.col(hem) = g.state.x.col(above) + (g.state.x.col(hem) - g.state.x.col(above)).normalized() * rest;
    g.counters.collision_tests = 400;
    g.counters.max_penetration_m = 0.002f;
    g.counters.substeps = 1;
    g.state.x(1, t.grid[5]) = std::numeric_limits<Real>::quiet_NaN();
    watch.sample(registry);

    const auto result = watch.result(registry);
    ASSERT_EQ(result.size(), 1u);
    EXPECT_EQ(result[0].particles, 16u);
    EXPECT_FALSE(std::isfinite(result[0].strain_max));  // a NaN spring is reported, not hidden
    EXPECT_NEAR(result[0].penetration_before_response_m, 0.01, 1e-6);
    EXPECT_EQ(result[0].nonfinite, 1u);
    EXPECT_DOUBLE_EQ(result[0].collision_tests_per_frame, 150.0);  // (400 - 100) tests over 2 frames
    EXPECT_DOUBLE_EQ(result[0].substeps_mean, 2.0);
    EXPECT_EQ(result[0].substeps_max, 3);
}

TEST(GarmentWatch, StrainIsMeasuredOnTheGarmentAfterTheFrame) {
    Registry registry;
    const Entity e = attach_small_rectangle(registry);
    Garment& g = registry.get<Garment>(e);
    GarmentWatch watch(registry, {e});
    const Fabric& t = *g.fabric;
    const std::uint32_t hem = t.grid[3], above = t.grid[2];
    g.state.x.col(hem) = g.state.x.col(above) + (g.state.x.col(hem) - g.state.x.col(above)) * Real(1.2);
    watch.sample(registry);
    const auto result = watch.result(registry);
    EXPECT_NEAR(result[0].strain_max, 0.2, 1e-4);
    EXPECT_GT(result[0].strain_p99, 0.0);  // the histogram saw the stretched springs
    EXPECT_EQ(result[0].pins_inside_m, 0.0);
    // Where it was: the warp spring from row 2 to the hem on line 0, in the first frame; the
    // rectangle hangs in the air (no ellipsoid near).
    const WorstSpring& worst = result[0].worst_spring;
    EXPECT_TRUE(worst.seen);
    EXPECT_EQ(worst.frame, 1u);
    EXPECT_FALSE(worst.weft);
    EXPECT_EQ(worst.line, 0u);
    EXPECT_EQ(worst.row, 2u);
    EXPECT_EQ(worst.rows, 4u);
    EXPECT_TRUE(worst.body_part.empty());
    EXPECT_FALSE(worst.straddles);
}

// The fastest free particle's stored velocity over the run: a pinned particle's is not the
// cloth's, and a later, slower frame does not lower it.
TEST(GarmentWatch, ReportsTheFastestFreeParticle) {
    Registry registry;
    const Entity e = attach_small_rectangle(registry);
    Garment& g = registry.get<Garment>(e);
    GarmentWatch watch(registry, {e});
    const Fabric& t = *g.fabric;
    const std::uint32_t pinned = t.grid[0], hem = t.grid[3];  // line 0: the top row is pinned
    ASSERT_EQ(g.state.inv_mass[pinned], 0);
    ASSERT_GT(g.state.inv_mass[hem], 0);
    g.state.v.setZero();
    g.state.v.col(pinned) = Vec3(0, 0, 90);
    g.state.v.col(hem) = Vec3(3, 0, 4);
    watch.sample(registry);
    g.state.v.col(hem) = Vec3(0, 1, 0);
    watch.sample(registry);
    EXPECT_NEAR(watch.result(registry)[0].speed_max_m_s, 5.0, 1e-6);
}

TEST(StatsFile, NoWorstSpringIsWrittenAsNull) {
    RunStats r = example();
    r.garments.back().worst_spring = {};
    const nlohmann::json j = nlohmann::json::parse(stats_json(r));
    EXPECT_TRUE(j["garments"][0]["strain"]["worst"].is_null());
}

}  // namespace
}  // namespace drape
