// Every bad input gives one line naming the file and the reason (never a crash).
#include <gtest/gtest.h>

#include <fstream>

#include "drape/engine/assets/character_import.hpp"
#include "tests/character/test_character_file.hpp"

namespace drape {
namespace {

ImportOptions test_options(bool require_animation) {
    ImportOptions o;
    o.require_animation = require_animation;
    return o;
}
ImportOptions zero_height() {
    ImportOptions o;
    o.height_m = 0.0;
    return o;
}

class BadInput : public ::testing::Test {
protected:
    void SetUp() override { dir = test::temp_dir("bad_input"); }
    void TearDown() override { std::filesystem::remove_all(dir); }

    // Imports and checks the error: one line, names the file, says `reason`.
    void expect_error(const std::filesystem::path& file, const std::string& reason, const ImportOptions& options = {}) {
        auto r = import_character(file, options);
        ASSERT_FALSE(r) << file << " imported";
        const std::string& m = r.error().message;
        EXPECT_NE(m.find(file.string()), std::string::npos) << m;
        EXPECT_NE(m.find(reason), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
    std::filesystem::path dir;
};

TEST_F(BadInput, MissingFile) { expect_error(dir / "nothing.glb", "no such file"); }

TEST_F(BadInput, NotAModel) {
    std::ofstream(dir / "notes.glb") << "these are my shopping notes, not a character\n";
    expect_error(dir / "notes.glb", "not a readable model");
}

TEST_F(BadInput, EmptyFile) {
    std::ofstream(dir / "empty.fbx");
    expect_error(dir / "empty.fbx", "empty file");
}

TEST_F(BadInput, TruncatedFile) {
    test::write_test_character({}, dir / "whole.gltf");
    std::ifstream in(dir / "whole.gltf", std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(dir / "cut.gltf", std::ios::binary) << text.substr(0, text.size() / 2);
    expect_error(dir / "cut.gltf", "not a readable model");
}

TEST_F(BadInput, TruncatedBinaryGlb) {
    // A glb header that promises more bytes than the file holds.
    std::string glb("glTF", 4);
    const std::uint32_t version = 2, length = 4096, chunk = 1000, json = 0x4E4F534A;
    glb.append(reinterpret_cast<const char*>(&version), 4).append(reinterpret_cast<const char*>(&length), 4);
    glb.append(reinterpret_cast<const char*>(&chunk), 4).append(reinterpret_cast<const char*>(&json), 4);
    glb += "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[";
    std::ofstream(dir / "cut.glb", std::ios::binary) << glb;
    expect_error(dir / "cut.glb", "not a readable model");
}

TEST_F(BadInput, NoSkeleton) {
    test::write_test_character({.skin = false, .animation = false}, dir / "statue.gltf");
    expect_error(dir / "statue.gltf", "no skeleton");
    expect_error(dir / "statue.gltf", "no skeleton", test_options(false));
}

TEST_F(BadInput, NoAnimation) {
    test::write_test_character({.animation = false}, dir / "still.gltf");
    expect_error(dir / "still.gltf", "no animation");
    EXPECT_TRUE(import_character(dir / "still.gltf", test_options(false)));
}

TEST_F(BadInput, ClipNameThatIsNotThere) {
    test::write_test_character({}, dir / "column.gltf");
    auto c = import_character(dir / "column.gltf");
    ASSERT_TRUE(c) << c.error().message;
    auto r = find_clip(**c, "Moonwalk");
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("column.gltf"), std::string::npos);
    EXPECT_NE(r.error().message.find("no clip named 'Moonwalk' (clips: 'Bend')"), std::string::npos) << r.error().message;
}

TEST_F(BadInput, NonFiniteRotationKey) {
    test::write_test_character({.nan_rotation_key = true}, dir / "nan_key.gltf");
    expect_error(dir / "nan_key.gltf", "clip 'Bend', bone 'Child': non-finite rotation key 1");
}

TEST_F(BadInput, NonFiniteWeight) {
    test::write_test_character({.nan_weight = true}, dir / "nan_weight.gltf");
    expect_error(dir / "nan_weight.gltf", "vertex 1 has no finite, positive bone weight");
}

TEST_F(BadInput, BadOptionNamesTheField) {
    test::write_test_character({}, dir / "column.gltf");
    expect_error(dir / "column.gltf", "height_m: must be a finite number > 0", zero_height());
}

}  // namespace
}  // namespace drape
