// The --stats file: exactly the documented fields, written atomically.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "components/garment.hpp"
#include "game/stats.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

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
    r.garments.push_back({.particles = 837, .max_strain = 0.1, .max_penetration_m = 0.004, .nonfinite = 0,
                          .collision_tests_per_frame = 1234.5});
    return r;
}

TEST(StatsFile, HasExactlyTheDocumentedFields) {
    const nlohmann::json j = nlohmann::json::parse(stats_json(example()));
    EXPECT_EQ(keys(j), (std::vector<std::string>{"frames", "garments", "sim_dt_s", "systems"}));
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
    EXPECT_EQ(keys(g), (std::vector<std::string>{"collision_tests_per_frame", "max_penetration_m", "max_strain", "nonfinite",
                                                 "particles"}));
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

TEST(GarmentWatch, ReportsWorstValuesAndNonFiniteParticles) {
    Registry registry;
    const Entity e = registry.create();
    Garment& g = registry.emplace<Garment>(e);
    g.state.x = Matrix3X::Zero(3, 4);
    g.state.v = Matrix3X::Zero(3, 4);
    g.counters.collision_tests = 100;  // before the run: not counted
    GarmentWatch watch(registry, {e});

    g.counters.max_strain = 0.05f;
    g.counters.max_penetration_m = 0.01f;
    watch.sample(registry);
    registry.get<Garment>(e).counters.collision_tests = 400;
    registry.get<Garment>(e).counters.max_strain = 0.02f;
    registry.get<Garment>(e).state.x(1, 2) = std::numeric_limits<Real>::quiet_NaN();
    watch.sample(registry);

    const auto result = watch.result(registry);
    ASSERT_EQ(result.size(), 1u);
    EXPECT_EQ(result[0].particles, 4u);
    EXPECT_FLOAT_EQ(static_cast<float>(result[0].max_strain), 0.05f);
    EXPECT_FLOAT_EQ(static_cast<float>(result[0].max_penetration_m), 0.01f);
    EXPECT_EQ(result[0].nonfinite, 1u);
    EXPECT_DOUBLE_EQ(result[0].collision_tests_per_frame, 150.0);  // (400 - 100) tests over 2 frames
}

}  // namespace
}  // namespace drape
