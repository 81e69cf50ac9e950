// Scene files: a valid file round-trips; every bad input gives one error line naming the
// file, line, column and field; random mutations never crash the parser.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "drape/game/scene_file.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

// A folder with a stand-in character file (the parser only checks that it exists).
class SceneFileTest : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() / ("drape_scene_file_test_" + std::to_string(::getpid()));
        fs::create_directories(m_dir / "chars");
        std::ofstream(m_dir / "chars" / "body.glb") << "stand-in";
    }
    void TearDown() override { fs::remove_all(m_dir); }

    // Writes `text` as scene.json and loads it.
    Result<SceneDescription> load(const std::string& text) {
        const fs::path file = m_dir / "scene.json";
        std::ofstream(file, std::ios::binary | std::ios::trunc) << text;
        return load_scene_file(file);
    }
    // The error for `text`, with the folder part of the file name removed.
    std::string error(const std::string& text) {
        auto r = load(text);
        if (r) return "(no error)";
        std::string m = r.error().message;
        const std::string prefix = (m_dir / "").string();
        if (m.rfind(prefix, 0) == 0) m = m.substr(prefix.size());
        return m;
    }
    fs::path m_dir;
};

constexpr const char* valid_scene = R"({
  "description": "two characters, a skirt and a dress",
  // comments are allowed
  "characters": [
    {"file": "chars/body.glb", "clip": "Walk", "scale": 1.0, "position_m": [0, 0, 0],
     "rotation_deg": [0, 90, 0], "speed": 1.25, "in_place": true},
    {"file": "chars/body.glb", "clip": 2, "position_m": [1.5, 0, -0.5], "in_place": false, "thicken_thin_trunk_m": 0}
  ],
  "garments": [
    {"type": "skirt", "character": 0, "model": "simplified", "collision": "lists",
     "color": [0.8, 0.1, 0.2], "particles": 837},
    {"type": "dress", "character": 1, "model": "classic", "integrator": "paper", "collision": "brute_force"}, {"warp_solve": "lines", "pin_weights": "skin_surface"}
  ],
  "colliders": [
    {"character": 0, "bone": "Hips", "radii_m": [0.2, 0.15, 0.14]},
    {"character": 1, "bone": "Head", "remove": true}
  ],
  "solver": {"fixed_dt_s": 0.008, "max_steps_per_frame": 6, "time_scale": 0.5, "substeps": 3,
             "max_surface_travel_m": 0.01, "max_substeps": 12, "max_frame_dt_s": 0.1, "teleport_threshold_m": 0.5, "threads": 2},
  "camera": {"follow": false, "target_m": [0, 1, 0], "distance_m": 4, "yaw_deg": 20,
             "pitch_deg": 10, "fov_deg": 45}
})";

TEST_F(SceneFileTest, ValidFileIsReadCompletely) {
    auto scene = load(valid_scene);
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_EQ(scene->characters.size(), 2u);
    EXPECT_EQ(scene->characters[0].file, (m_dir / "chars" / "body.glb").lexically_normal());
    EXPECT_EQ(scene->characters[0].clip, "Walk");
    EXPECT_EQ(scene->characters[1].clip, "2");
    EXPECT_DOUBLE_EQ(scene->characters[0].speed, 1.25);
    EXPECT_FALSE(scene->characters[1].in_place);
    EXPECT_FLOAT_EQ(scene->characters[1].position_m.x(), 1.5f);
    EXPECT_EQ(scene->characters[0].thicken_thin_trunk_m, default_thicken_thin_trunk_m);
    EXPECT_EQ(scene->characters[1].thicken_thin_trunk_m, 0.0);
    // Yaw 90 degrees turns +Z to +X.
    EXPECT_TRUE((scene->characters[0].rotation() * Vec3::UnitZ()).isApprox(Vec3::UnitX(), 1e-5f));
    ASSERT_EQ(scene->garments.size(), 3u);
    EXPECT_EQ(scene->garments[0].type, GarmentType::skirt);
    ASSERT_EQ(scene->garments[0].parameters.size(), 1u);
    EXPECT_EQ(scene->garments[0].parameters[0].name, "particles");
    EXPECT_EQ(scene->garments[0].parameters[0].value, 837);
    EXPECT_EQ(scene->garments[1].model, ClothModel::classic);
    EXPECT_EQ(scene->garments[1].collision, CollisionMode::brute_force);
    EXPECT_EQ(scene->garments[0].integrator, ClothIntegrator::shipped);
    EXPECT_EQ(scene->garments[1].integrator, ClothIntegrator::paper);
    EXPECT_EQ(scene->garments[1].warp_solve, WarpSolve::rounds);
    EXPECT_EQ(scene->garments[2].warp_solve, WarpSolve::lines);
    EXPECT_EQ(scene->garments[1].pin_weights, PinWeights::nearest_vertex);
    EXPECT_EQ(scene->garments[2].pin_weights, PinWeights::skin_surface);
    EXPECT_FALSE(scene->garments[1].color.has_value());
    ASSERT_EQ(scene->colliders.size(), 2u);
    EXPECT_TRUE(scene->colliders[1].remove);
    EXPECT_EQ(scene->solver.substeps, 3);
    EXPECT_EQ(scene->solver.threads, 2);
    EXPECT_DOUBLE_EQ(scene->solver.max_surface_travel_m, 0.01);
    EXPECT_EQ(scene->solver.max_substeps, 12);
    EXPECT_DOUBLE_EQ(scene->solver.teleport_threshold_m, 0.5);
    EXPECT_FALSE(scene->camera.follow);
    EXPECT_FLOAT_EQ(scene->camera.fov_deg, 45);
    // Locations for later (load-time) errors.
    EXPECT_EQ(scene->characters[0].where.line, 5);
    EXPECT_EQ(scene->colliders[0].where.line, 15);
}

TEST_F(SceneFileTest, WrittenJsonReadsBackEqual) {
    auto scene = load(valid_scene);
    ASSERT_TRUE(scene) << scene.error().message;
    auto again = parse_scene(to_json(*scene), "", "");
    ASSERT_TRUE(again) << again.error().message;
    // Source locations differ by construction; everything else must not.
    SceneDescription a = *scene, b = *again;
    for (auto* s : {&a, &b}) {
        for (auto& c : s->characters) c.where = {};
        for (auto& g : s->garments) g.where = {};
        for (auto& c : s->colliders) c.where = {};
    }
    EXPECT_EQ(a, b);
    EXPECT_EQ(to_json(*scene), to_json(*again));
}

TEST_F(SceneFileTest, MinimalFileTakesDefaults) {
    auto scene = load(R"({"characters": [{"file": "chars/body.glb"}]})");
    ASSERT_TRUE(scene) << scene.error().message;
    EXPECT_TRUE(scene->garments.empty());
    EXPECT_EQ(scene->solver, SolverDescription{});
    EXPECT_EQ(scene->camera, CameraDescription{});
    EXPECT_TRUE(validate(*scene));
}

TEST_F(SceneFileTest, SyntaxErrorNamesLineAndColumn) {
    // Line 3 lacks a comma: the error is at the end of the unexpected "garments".
    EXPECT_EQ(error("{\n  \"characters\": [{\"file\": \"chars/body.glb\"}]\n  \"garments\": []\n}"),
              "scene.json:3:12: syntax error while parsing object - unexpected string literal; expected '}'");
    EXPECT_EQ(error("{\"characters\": [1,]}"),
              "scene.json:1:19: syntax error while parsing value - unexpected ']'; expected '[', '{', or a literal");
    EXPECT_NE(error("").find("scene.json:1:1: "), std::string::npos);
    EXPECT_NE(error("{\"characters\": ").find("scene.json:1:16: "), std::string::npos);
}

TEST_F(SceneFileTest, FieldErrorPointsAtTheValue) {
    const std::string text = "{\n"
                             "  \"characters\": [{\"file\": \"chars/body.glb\"}],\n"
                             "  \"garments\": [\n"
                             "    {\"type\": \"skirt\",\n"
                             "     \"particles\": -3}\n"
                             "  ]\n"
                             "}";
    EXPECT_EQ(error(text), "scene.json:5:19: garments[0].particles: must be an integer in [16, 250000], got -3");
}

TEST_F(SceneFileTest, WrongTypesAreNamed) {
    const std::string head = R"({"characters": [{"file": "chars/body.glb", )";
    EXPECT_EQ(error(head + R"("scale": "big"}]})"),
              "scene.json:1:53: characters[0].scale: must be a number in (0, 1000], got string \"big\"");
    EXPECT_EQ(error(head + R"("in_place": 1}]})"), "scene.json:1:56: characters[0].in_place: must be true or false, got number 1");
    EXPECT_EQ(error(head + R"("thicken_thin_trunk_m": 0.2}]})"),
              "scene.json:1:68: characters[0].thicken_thin_trunk_m: must be a number in [0, 0.1], got 0.2");
    EXPECT_EQ(error(head + R"("position_m": [0, "a", 0]}]})"),
              "scene.json:1:62: characters[0].position_m[1]: must be a number in [-10000, 10000], got string \"a\"");
    EXPECT_EQ(error(R"({"characters": {"file": "chars/body.glb"}})"),
              "scene.json:1:16: characters: must be an array ([...]), got object {\"file\":\"chars/body.glb\"}");
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb"}], "garments": [{"type": "shirt"}]})"),
              "scene.json:1:68: garments[0].type: must be one of \"skirt\", \"dress\", got \"shirt\"");
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb"}], "garments": [{"integrator": "implicit"}]})"),
              "scene.json:1:74: garments[0].integrator: must be one of \"shipped\", \"paper\", got \"implicit\"");
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb"}], "garments": [{"warp_solve": "direct"}]})"),
              "scene.json:1:74: garments[0].warp_solve: must be one of \"rounds\", \"lines\", got \"direct\"");
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb"}], "garments": [{"pin_weights": "nearest"}]})"),
              "scene.json:1:75: garments[0].pin_weights: must be one of \"nearest_vertex\", \"skin_surface\", got \"nearest\"");
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb"}], "solver": {"substeps": 2.5}})"),
              "scene.json:1:69: solver.substeps: must be \"auto\" or an integer in [1, 1000], got 2.5");
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb"}], "solver": {"max_surface_travel_m": 0}})"),
              "scene.json:1:81: solver.max_surface_travel_m: must be a number in (0, 1], got 0");
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb"}], "solver": {"max_substeps": 0}})"),
              "scene.json:1:73: solver.max_substeps: must be an integer in [1, 1000], got 0");
    EXPECT_EQ(error("[1, 2]"), "scene.json:1:1: must be an object ({...}), got array [1,2]");
}

TEST_F(SceneFileTest, UnknownFieldsAreErrorsWithASuggestion) {
    const std::string message = error(R"({"characters": [{"file": "chars/body.glb", "sclae": 2}]})");
    EXPECT_EQ(message.rfind("scene.json:1:44: characters[0].sclae: unknown field (did you mean \"scale\"?); known fields: file, clip,", 0), 0u)
        << message;
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb"}], "camera": {"zoom": 2}})").rfind("scene.json:1:57: camera.zoom: unknown field; known fields: follow,", 0),
              0u);
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb"}], "extra": 1})").rfind("scene.json:1:46: extra: unknown field", 0), 0u);
    // A skirt parameter name is not a dress field unless the dress has it too.
    EXPECT_NE(error(R"({"characters": [{"file": "chars/body.glb"}], "garments": [{"type": "skirt", "particle": 800}]})")
                  .find("garments[0].particle: unknown field (did you mean \"particles\"?)"),
              std::string::npos);
}

TEST_F(SceneFileTest, DuplicateFieldsAreErrors) {
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb", "scale": 1, "scale": 2}]})"),
              "scene.json:1:56: characters[0].scale: duplicate field (each field may appear once)");
}

TEST_F(SceneFileTest, ZeroNegativeAndNonFiniteSizesAreRejected) {
    const std::string head = R"({"characters": [{"file": "chars/body.glb"}], )";
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb", "scale": 0}]})"),
              "scene.json:1:53: characters[0].scale: must be a number in (0, 1000], got 0");
    EXPECT_EQ(error(head + R"("colliders": [{"bone": "Hips", "radii_m": [0.1, -0.2, 0.1]}]})"),
              "scene.json:1:94: colliders[0].radii_m[1]: must be a number in (0, 10], got -0.2");
    EXPECT_EQ(error(head + R"("camera": {"distance_m": 0}})"),
              "scene.json:1:71: camera.distance_m: must be a number in [0.3, 50], got 0");
    EXPECT_EQ(error(head + R"("solver": {"fixed_dt_s": -0.01}})"),
              "scene.json:1:71: solver.fixed_dt_s: must be a number in (0, 1], got -0.01");
    EXPECT_EQ(error(head + R"("solver": {"time_scale": 1e400}})"),
              "scene.json:1:71: number overflow parsing '1e400' (numbers must be finite and fit a double)");
}

TEST_F(SceneFileTest, AbsurdParticleCountsAreRejected) {
    const std::string head = R"({"characters": [{"file": "chars/body.glb"}], "garments": [{"particles": )";
    EXPECT_EQ(error(head + "2000000}]}"), "scene.json:1:73: garments[0].particles: must be an integer in [16, 250000], got 2000000");
    EXPECT_EQ(error(head + "18446744073709551616}]}"),
              "scene.json:1:73: garments[0].particles: must be an integer in [16, 250000], got number 1.8446744073709552e+19");
    EXPECT_EQ(error(head + "0}]}"), "scene.json:1:73: garments[0].particles: must be an integer in [16, 250000], got 0");
    // The limit is the garment builders' own, so a scene, a command line and C++ agree.
    EXPECT_EQ(max_scene_particles, max_garment_particles);
    EXPECT_EQ(error(head + "1000000}]}"), "scene.json:1:73: garments[0].particles: must be an integer in [16, 250000], got 1000000");
    const std::string grid = R"({"characters": [{"file": "chars/body.glb"}], "garments": [{"warp_lines": 999, "particles_per_line": 999}]})";
    EXPECT_EQ(error(grid), "scene.json:1:74: garments[0].warp_lines: warp_lines x particles_per_line must be at most 250000 particles, got 998001");
}

TEST_F(SceneFileTest, MissingCharacterFileNamesFileAndField) {
    const std::string message = error("{\n  \"characters\": [\n    {\"file\": \"chars/nobody.glb\"}\n  ]\n}");
    EXPECT_EQ(message, "scene.json:3:14: characters[0].file: no such file: " + (m_dir / "chars" / "nobody.glb").string());
    EXPECT_EQ(error(R"({"characters": [{"file": "chars"}]})"),
              "scene.json:1:26: characters[0].file: not a regular file: " + (m_dir / "chars").string());
    EXPECT_EQ(error(R"({"characters": [{"clip": "Walk"}]})"), "scene.json:1:17: characters[0].file: missing (a required field)");
    EXPECT_EQ(error(R"({"characters": []})"), "scene.json:1:16: characters: must list at least one character");
}

TEST_F(SceneFileTest, GarmentMustNameAnExistingCharacter) {
    EXPECT_EQ(error(R"({"characters": [{"file": "chars/body.glb"}], "garments": [{"character": 1}]})"),
              "scene.json:1:73: garments[0].character: must be an integer in [0, 0], got 1");
}

TEST_F(SceneFileTest, MissingSceneFileIsOneError) {
    auto r = load_scene_file(m_dir / "nothing.json");
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message, (m_dir / "nothing.json").string() + ": no such scene file");
}

TEST_F(SceneFileTest, DeepNestingIsAnErrorNotACrash) {
    const std::string deep = R"({"characters": [{"file": "chars/body.glb"}], "description": )" + std::string(100000, '[') +
                             std::string(100000, ']') + "}";
    const std::string message = error(deep);
    EXPECT_NE(message.find("nested deeper than 64 levels"), std::string::npos) << message.substr(0, 200);
}

TEST_F(SceneFileTest, CodeBuiltDescriptionsAreValidatedWithFieldNames) {
    SceneDescription scene;
    scene.characters.emplace_back();
    scene.characters[0].file = m_dir / "chars" / "body.glb";
    EXPECT_TRUE(validate(scene));
    scene.garments.emplace_back();
    scene.garments[0].parameters = {{"particles", 5e6}};
    auto r = validate(scene);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message, "garments[0].particles: must be an integer in [16, 250000], got 5000000");
}

// Random byte-level and token-level mutations of a valid scene: the parser must always
// return either a description or one line of error, never crash or hang. Bounded by a
// fixed number of cases (deterministic seed).
TEST_F(SceneFileTest, RandomMutationsNeverCrash) {
    const std::string base = valid_scene;
    const std::vector<std::string> tokens = {"{", "}", "[", "]", ",", ":", "\"", "-1", "0", "1e308", "1e999", "null",
                                             "true", "\"x\"", "\"particles\"", "\"file\"", "2000000", "/*", "\\u0000", "\xff"};
    std::mt19937 rng(12345);
    int parsed = 0, rejected = 0;
    for (int i = 0; i < 3000; ++i) {
        std::string text = base;
        const int edits = 1 + static_cast<int>(rng() % 4);
        for (int e = 0; e < edits; ++e) {
            const std::size_t at = rng() % (text.size() + 1);
            switch (rng() % 4) {
                case 0: text.insert(at, tokens[rng() % tokens.size()]); break;
                case 1: if (at < text.size()) text.erase(at, 1 + rng() % 8); break;
                case 2: if (at < text.size()) text[at] = static_cast<char>(rng() % 256); break;
                case 3: text = text.substr(0, at); break;
            }
        }
        auto r = parse_scene(text, "fuzz.json", m_dir);
        if (r) {
            ++parsed;
            EXPECT_TRUE(validate(*r)) << "accepted text fails validation:\n" << text;
        } else {
            ++rejected;
            const std::string& m = r.error().message;
            EXPECT_FALSE(m.empty());
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
            EXPECT_EQ(m.rfind("fuzz.json:", 0), 0u) << m;
        }
    }
    EXPECT_GT(rejected, 0);
    EXPECT_GT(parsed, 0);  // some mutations (inside strings, numbers) stay valid
}

}  // namespace
}  // namespace drape
