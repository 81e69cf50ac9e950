// Fitted bodies kept on disk (systems/character/body_cache.hpp): a world built from a cached body is the
// world a fit gives, the cache is what it reads, and anything that changes the fit, or a
// damaged file, fits again.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "drape/components/body_landmarks.hpp"
#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/systems/character/body_cache.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/world.hpp"
#include "drape/systems/character/spawn.hpp"
#include "tests/character/test_character_file.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

// The fitted shapes of the world's first character, its landmarks' heights, and its
// garment after ten frames.
struct Seen {
    std::vector<EllipsoidShape> shapes;
    std::vector<Real> landmarks;
    Matrix3X garment;
};

Seen build_and_step(const fs::path& cache) {
    WorldOptions options;
    options.body_cache = cache;
    auto world = build_world(sample_scene(), options);
    EXPECT_TRUE(world) << (world ? "" : world.error().message);
    if (!world) return {};
    Seen seen;
    for (Entity e : colliders_of(world->registry, world->characters.at(0))) {
        const EllipsoidCollider& c = world->registry.get<EllipsoidCollider>(e);
        seen.shapes.push_back({c.bone, c.center, c.rotation, c.radii_m, c.region, c.give_m});
    }
    const BodyLandmarks& l = world->registry.get<BodyLandmarks>(world->characters.at(0));
    seen.landmarks = {l.floor_m, l.top_m, l.crotch_m, l.underarm_m, l.waist.girth_m, l.hips.girth_m, l.chest.girth_m,
                      l.left_shoulder.rest_m.x(), Real(l.spine.size()), Real(l.body_bones.size())};
    for (int frame = 0; frame < 10; ++frame) EXPECT_TRUE(step_world(*world, 1.0 / 60.0));
    seen.garment = world->registry.get<Garment>(world->garments.at(0)).state.x;
    return seen;
}

void expect_same(const Seen& a, const Seen& b) {
    ASSERT_EQ(a.shapes.size(), b.shapes.size());
    for (std::size_t i = 0; i < a.shapes.size(); ++i) {
        EXPECT_EQ(a.shapes[i].bone, b.shapes[i].bone) << i;
        EXPECT_TRUE(a.shapes[i].center == b.shapes[i].center) << i;
        EXPECT_TRUE(a.shapes[i].rotation.coeffs() == b.shapes[i].rotation.coeffs()) << i;
        EXPECT_TRUE(a.shapes[i].radii_m == b.shapes[i].radii_m) << i;
        EXPECT_EQ(a.shapes[i].region, b.shapes[i].region) << i;
        EXPECT_EQ(a.shapes[i].give_m, b.shapes[i].give_m) << i;
    }
    EXPECT_EQ(a.landmarks, b.landmarks);
    EXPECT_TRUE(a.garment == b.garment);
}

std::string read(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out << bytes;
}

TEST(BodyCache, AWorldFromTheCacheIsTheWorldAFitGivesAndTheCacheIsWhatItReads) {
    const fs::path cache = test::temp_dir("body_cache");
    const Seen fitted = build_and_step(cache);  // fits and keeps the body
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(cache)) files.push_back(entry.path());
    ASSERT_EQ(files.size(), 1u) << "one body kept for the one character";
    EXPECT_EQ(files[0].extension(), ".body");

    expect_same(build_and_step(cache), fitted);  // read back: the same world, byte for byte

    // The second world read the file: a radius changed in it reaches the world. The first
    // shape's first radius is the float after the key text and the shape's bone, centre
    // and rotation (body_cache.cpp's body_fields).
    const std::string original = read(files[0]);
    const auto key = body_cache_key(sample_scene().characters.at(0).file, FitOptions{});
    ASSERT_TRUE(key);
    ASSERT_EQ(original.compare(0, key->text.size(), key->text), 0) << "the file starts with its key";
    std::string changed = original;
    const std::size_t radius = key->text.size() + 4 + 4 + 12 + 16;
    float r = 0;
    std::memcpy(&r, changed.data() + radius, sizeof r);
    ASSERT_GT(r, 0);
    r *= 2;
    std::memcpy(changed.data() + radius, &r, sizeof r);
    write(files[0], changed);
    const Seen from_changed = build_and_step(cache);
    ASSERT_FALSE(from_changed.shapes.empty());
    EXPECT_EQ(from_changed.shapes[0].radii_m.x(), r);

    // A damaged file is a missed cache, not a wrong body.
    write(files[0], original.substr(0, original.size() - 3));
    EXPECT_FALSE(read_cached_body(cache, *key));
    write(files[0], original + "x");
    EXPECT_FALSE(read_cached_body(cache, *key));
    write(files[0], original);
    EXPECT_TRUE(read_cached_body(cache, *key));
    fs::remove_all(cache);
}

// What the fit depends on is in the key: the options, the threads, the file's bytes
// and the files beside it.
TEST(BodyCache, TheKeyChangesWithWhatTheFitDependsOn) {
    const fs::path dir = test::temp_dir("body_cache_key");
    const fs::path file = dir / "column.gltf";
    test::write_test_character({}, file);
    const auto base = body_cache_key(file, FitOptions{});
    ASSERT_TRUE(base);
    EXPECT_EQ(body_cache_key(file, FitOptions{})->name, base->name) << "the same fit, the same key";
    FitOptions other;
    other.max_ellipsoids = 12;
    EXPECT_NE(body_cache_key(file, other)->text, base->text);
    {
        tbb::task_arena one(1);
        one.execute([&] { EXPECT_NE(body_cache_key(file, FitOptions{})->text, base->text) << "one thread"; });
    }
    write(dir / "column.bin", "buffer");
    EXPECT_NE(body_cache_key(file, FitOptions{})->text, base->text) << "a file beside it";
    const auto with_buffer = body_cache_key(file, FitOptions{});
    write(file, read(file) + " ");
    EXPECT_NE(body_cache_key(file, FitOptions{})->text, with_buffer->text) << "its bytes";
    EXPECT_FALSE(body_cache_key(dir / "missing.gltf", FitOptions{})) << "no file, no key";
    fs::remove_all(dir);
}

}  // namespace
}  // namespace drape
