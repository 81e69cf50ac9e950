// Where Drape has to guess about a character, `drape play` says so in one line each
// (World::warnings): units it could not take from the file, landmarks it could not find,
// a clip chosen for want of a walk or a run. A character it need not guess about gets none.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "drape/engine/assets/character_import.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/world.hpp"
#include "tests/character/test_character_file.hpp"
#include "tests/shared_assets.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

int lines_with(const World& world, const std::string& text) {
    return static_cast<int>(std::count_if(world.warnings.begin(), world.warnings.end(),
                                          [&](const std::string& w) { return w.find(text) != std::string::npos; }));
}

SceneDescription alone(const fs::path& file) {
    SceneDescription scene;
    scene.characters.emplace_back();
    scene.characters[0].file = file;
    return scene;
}

TEST(WhatPlaySays, NothingAboutTheDefaultAvatar) {
    auto world = build_world(sample_scene(), {});
    ASSERT_TRUE(world) << world.error().message;
    EXPECT_TRUE(world->warnings.empty()) << world->warnings.front();
}

// A glTF column 2 m tall (metres, as glTF states), one clip "Bend", no humanoid: its units
// are the file's, its landmarks and its clip are guesses.
TEST(WhatPlaySays, OneLineWhenTheLandmarksOrTheClipFallBack) {
    const auto dir = test::temp_dir("what_play_says");
    const fs::path file = dir / "column.gltf";
    test::write_test_character({}, file);
    auto world = build_world(alone(file), {});
    fs::remove_all(dir);
    ASSERT_TRUE(world) << world.error().message;
    EXPECT_EQ(lines_with(*world, "units:"), 0);
    EXPECT_EQ(lines_with(*world, "body landmarks: "), 1);
    EXPECT_EQ(lines_with(*world, "garments hang at a fixed share of its height"), 1);
    EXPECT_EQ(lines_with(*world, "clip: no walk and no looping locomotion clip; playing Bend (first clip"), 1);
    EXPECT_EQ(world->warnings.size(), 2u);
}

// The Quaternius files state centimetres (UnitScaleFactor 1) and would stand 4.8 m tall in
// them: the standard height is kept, and the line says why.
TEST(WhatPlaySays, OneLineWhenTheFileUnitsAreNotUsed) {
    const fs::path file = test::shared_assets() / "characters/male_casual/Male_Casual.fbx";
    DRAPE_REQUIRE_SHARED(file);
    auto imported = import_character(file);
    ASSERT_TRUE(imported) << imported.error().message;
    EXPECT_EQ((*imported)->scale_source, ScaleSource::fallback);
    EXPECT_NE((*imported)->units_note.find("FBX: UnitScaleFactor 1 (1 unit = 1 cm), UpAxis Y"), std::string::npos)
        << (*imported)->units_note;
    auto world = build_world(alone(file), {});
    ASSERT_TRUE(world) << world.error().message;
    ASSERT_EQ(lines_with(*world, "units: "), 1);
    EXPECT_EQ(lines_with(*world, "outside 0.3-2.6 m: scaled to 1.75 m instead"), 1);
    EXPECT_EQ(world->warnings.size(), 1u) << world->warnings.back();  // its walk is a walk, its landmarks found
}

}  // namespace
}  // namespace drape
