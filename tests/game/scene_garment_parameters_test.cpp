// Garment parameters from scene files: every row of the cloth module's parameter table is a
// scene field checked against the same range validate(TubeParams) checks, reaches its
// TubeParams field; a misspelt name is an error naming it.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "drape/game/scene_file.hpp"
#include "drape/game/scene_garment_parameters.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_parameters.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

// A folder with a stand-in character file (the parser only checks that it exists).
class SceneGarmentParameters : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() / ("drape_scene_garment_parameters_test_" + std::to_string(::getpid()));
        fs::create_directories(m_dir);
        std::ofstream(m_dir / "body.glb") << "stand-in";
    }
    void TearDown() override { fs::remove_all(m_dir); }

    // A scene whose only garment (of `type`) has `fields` (JSON members, e.g. "\"length_m\": 2").
    Result<SceneDescription> load(const std::string& type, const std::string& fields) {
        const fs::path file = m_dir / "scene.json";
        std::ofstream(file, std::ios::binary | std::ios::trunc)
            << "{\"characters\": [{\"file\": \"body.glb\"}],\n \"garments\": [{\"type\": \"" << type << "\", " << fields << "}]}";
        return load_scene_file(file);
    }
    // The error without the folder part of the file name ("(no error)" when it loads).
    std::string error(const std::string& type, const std::string& fields) {
        auto r = load(type, fields);
        if (r) return "(no error)";
        std::string m = r.error().message;
        const std::string prefix = (m_dir / "").string();
        if (m.rfind(prefix, 0) == 0) m = m.substr(prefix.size());
        return m;
    }
    fs::path m_dir;
};

// A number as JSON text that reads back as exactly `v` (a Real value reads back as that Real).
std::string json_number(double v) {
    std::ostringstream out;
    out.precision(17);
    out << v;
    return out.str();
}

// `"name": value` (built by appending: GCC 12 warns falsely on "literal" + std::string temporaries).
std::string member(std::string_view name, double value) {
    std::string s = "\"";
    s += name;
    s += "\": ";
    s += json_number(value);
    return s;
}

// Values just outside a row's range, and values at or just inside its ends. A real's
// neighbours are those of a Real, so the builder sees them outside (or inside) too.
struct Probe {
    double value;
    bool inside;
};
std::vector<Probe> probes(const ParameterSpec& spec) {
    const ParameterRange& r = spec.range;
    if (spec.kind == ParameterKind::integer)
        return {{r.min - 1, false}, {r.max + 1, false}, {r.min, true}, {r.max, true}};
    const auto below = [](double x) { return double(std::nextafter(Real(x), -std::numeric_limits<Real>::infinity())); };
    const auto above = [](double x) { return double(std::nextafter(Real(x), std::numeric_limits<Real>::infinity())); };
    return {{r.min_open ? r.min : below(r.min), false},
            {r.max_open ? r.max : above(r.max), false},
            {r.min_open ? above(r.min) : r.min, true},
            {r.max_open ? below(r.max) : r.max, true}};
}

TEST_F(SceneGarmentParameters, EveryRangeIsEnforcedByTheSceneFileAndByValidate) {
    int checked = 0;
    for (const GarmentParameterSpec& spec : garment_parameters()) {
        const std::string name(spec.name);
        for (const Probe& probe : probes(spec)) {
            for (const std::string type : {"skirt", "dress"}) {
                SCOPED_TRACE(type + "." + name + " = " + json_number(probe.value));
                // The scene file.
                const std::string scene_error = error(type, member(name, probe.value));
                const std::string scene_says = "garments[0]." + name + ": must be " +
                                               (spec.kind == ParameterKind::integer ? "an integer" : "a number") + " in " +
                                               spec.range.text() + ", got ";
                if (probe.inside)
                    EXPECT_EQ(scene_error, "(no error)");
                else
                    EXPECT_EQ(scene_error.rfind("scene.json:2:", 0), 0u) << scene_error;
                EXPECT_EQ(scene_error.find(scene_says) != std::string::npos, !probe.inside) << scene_error;
                // The builder's own check.
                TubeParams params = type == "skirt" ? TubeParams::skirt() : TubeParams::dress();
                spec.set(params, probe.value);
                const auto valid = validate(params, type);
                const std::string builder_says = type + "." + spec.field() + ": must be in " + spec.range.text();
                if (probe.inside) {
                    // Inside its range a value may still break a combination, never its own range.
                    if (!valid) {
                        EXPECT_NE(valid.error().message.rfind(builder_says, 0), 0u) << valid.error().message;
                    }
                } else {
                    ASSERT_FALSE(valid);
                    EXPECT_EQ(valid.error().message.rfind(builder_says, 0), 0u) << valid.error().message;
                }
                ++checked;
            }
        }
    }
    EXPECT_EQ(checked, static_cast<int>(garment_parameters().size()) * 4 * 2);
}

TEST_F(SceneGarmentParameters, AMisspeltParameterNameIsAnErrorNamingIt) {
    // On line 2 of the file, at the misspelt key.
    const std::string message = error("skirt", "\"strech_N_m\": 2");
    EXPECT_EQ(message.rfind("scene.json:2:33: garments[0].strech_N_m: unknown field (did you mean \"stretch_N_m\"?); "
                            "known fields: type, character, model, integrator, warp_solve, pin_weights, collision, color, material, particles, warp_lines,",
                            0),
              0u)
        << message;
    // Far from every name: no suggestion, still an error naming it.
    EXPECT_EQ(error("dress", "\"stiffness\": 2").rfind("scene.json:2:33: garments[0].stiffness: unknown field; known fields:", 0), 0u);
    // A description built in code is checked the same way, without a position.
    SceneDescription scene;
    scene.characters.emplace_back();
    scene.characters[0].file = m_dir / "body.glb";
    scene.garments.emplace_back();
    scene.garments[0].parameters = {{"lenght_m", 0.5}};
    auto r = validate(scene);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().message.rfind("garments[0].lenght_m: unknown field (did you mean \"length_m\"?)", 0), 0u) << r.error().message;
    // And the mapping onto the builder refuses it rather than ignoring it.
    auto params = tube_params(scene.garments[0]);
    ASSERT_FALSE(params);
    EXPECT_EQ(params.error().message, "lenght_m: unknown garment parameter (docs/scenes.md lists them)");
}

TEST_F(SceneGarmentParameters, AMaterialPresetByNameThenItsFieldsOverridden) {
    auto scene = load("skirt", "\"material\": \"denim\", \"friction\": 0.2");
    ASSERT_TRUE(scene) << scene.error().message;
    auto params = tube_params(scene->garments.at(0));
    ASSERT_TRUE(params) << params.error().message;
    ClothMaterial expected = *material_preset("denim");
    expected.friction = Real(0.2);
    EXPECT_EQ(params->material, expected);
    EXPECT_EQ(error("skirt", "\"material\": \"tweed\"").rfind(
                  "scene.json:2:45: garments[0].material: must be one of \"silk\", \"cotton\", \"denim\", got \"tweed\"", 0),
              0u)
        << error("skirt", "\"material\": \"tweed\"");
    EXPECT_NE(error("skirt", "\"material\": 3").find("garments[0].material: must be one of"), std::string::npos);
}

TEST_F(SceneGarmentParameters, FormerRingHeightNamesSayTheNewName) {
    EXPECT_EQ(error("skirt", "\"waist_height_m\": 0.9"),
              "scene.json:2:33: garments[0].waist_height_m: renamed ring_height_m (the ring is the waist of a skirt, the shoulders of a dress)");
    EXPECT_EQ(error("dress", "\"shoulder_height_fraction\": 0.8"),
              "scene.json:2:33: garments[0].shoulder_height_fraction: renamed ring_height_fraction (the ring is the waist of a skirt, "
              "the shoulders of a dress)");
}

TEST_F(SceneGarmentParameters, EveryRowReachesItsFieldFromASceneFile) {
    for (const GarmentParameterSpec& spec : garment_parameters()) {
        SCOPED_TRACE(std::string(spec.name));
        // A value inside the range that differs from both defaults.
        const ParameterRange& r = spec.range;
        double value = spec.kind == ParameterKind::integer ? std::floor((r.min + std::min(r.max, r.min + 20)) / 2) + 1
                                                           : r.min + (std::min(r.max, r.min + 1) - r.min) * 0.37;
        ASSERT_TRUE(r.contains(value));
        for (const std::string type : {"skirt", "dress"}) {
            const TubeParams defaults = type == "skirt" ? TubeParams::skirt() : TubeParams::dress();
            ASSERT_NE(spec.get(defaults), double(Real(value)));
            auto scene = load(type, member(spec.name, value));
            ASSERT_TRUE(scene) << scene.error().message;
            auto params = tube_params(scene->garments.at(0));
            ASSERT_TRUE(params) << params.error().message;
            EXPECT_EQ(spec.get(*params), spec.kind == ParameterKind::integer ? value : double(Real(value)));
            // Nothing else moved.
            for (const GarmentParameterSpec& other : garment_parameters())
                if (&other != &spec) {
                    EXPECT_EQ(other.get(*params), other.get(defaults)) << other.name;
                }
        }
    }
}

TEST_F(SceneGarmentParameters, ParticlesChoosesAGridInTheTypesProportions) {
    auto scene = load("dress", "\"particles\": 2520, \"weft_stride\": 4");
    ASSERT_TRUE(scene) << scene.error().message;
    auto params = tube_params(scene->garments.at(0));
    ASSERT_TRUE(params) << params.error().message;
    EXPECT_EQ(params->weft_stride, 4);
    EXPECT_EQ(params->warp_lines % 4, 0);
    EXPECT_NEAR(params->warp_lines * params->particles_per_line, 2520, 2520 * 0.05);
    EXPECT_NEAR(double(params->particles_per_line) / params->warp_lines, 84.0 / 120.0, 0.1);
    EXPECT_TRUE(validate(*params, "dress"));
}

}  // namespace
}  // namespace drape
