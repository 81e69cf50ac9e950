// Garments from files (docs/garments.md): a built-in garment written as glTF
// (garment_as_mesh, write_garment_mesh) and read back (import_garment_mesh, grid_from_mesh,
// a scene's garment "file") is the same cloth; pins painted or automatic; a mesh resampled
// at another spacing; and every bad file or field refused with one line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <unistd.h>

#include <stb/stb_image_write.h>

#include "drape/components/garment.hpp"
#include "drape/components/garment_surface.hpp"
#include "drape/components/body_landmarks.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/engine/assets/garment_file.hpp"
#include "drape/game/contract.hpp"
#include "drape/game/garment_patterns.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/scene_file.hpp"
#include "drape/game/stats.hpp"
#include "drape/game/world.hpp"
#include "drape/systems/cloth/garment_from_mesh.hpp"
#include "drape/systems/cloth/garment_parameters.hpp"
#include "drape/systems/cloth/garment_surface.hpp"
#include "drape/systems/render_system.hpp"
#include "drape/systems/garment_surface_system.hpp"
#include "tests/test_paths.hpp"
#include "tests/figures.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

class GarmentFile : public ::testing::Test {
protected:
    void SetUp() override {
        dir = fs::temp_directory_path() / ("drape_garment_file_" + std::to_string(::getpid()));
        fs::remove_all(dir);
        fs::create_directories(dir);
    }
    void TearDown() override { fs::remove_all(dir); }

    // The sample scene's avatar in one garment, put on and not settled.
    static SceneDescription put_on(const GarmentDescription& garment) {
        SceneDescription scene = sample_scene();
        scene.garments = {garment};
        scene.solver.settle_s = 0;
        return scene;
    }
    static GarmentDescription built_in(GarmentType type) {
        GarmentDescription g;
        g.type = type;
        return g;
    }
    GarmentDescription from_file(const fs::path& file) const {
        GarmentDescription g;
        g.file = file;
        return g;
    }
    // `type` as the sample scene puts it on, as a mesh.
    static GarmentMeshAsset exported(GarmentType type) {
        auto world = build_world(put_on(built_in(type)), {});
        EXPECT_TRUE(world) << world.error().message;
        if (!world) return {};
        return garment_as_mesh(world->registry, world->garments.at(0));
    }

    fs::path dir;
};

// Particle (line, row) of a garment's grid.
Vec3 at(const Garment& g, std::uint32_t line, std::uint32_t row) {
    return g.state.x.col(g.fabric->grid[line * g.fabric->particles_per_line + row]);
}

TEST_F(GarmentFile, TheBuiltInSkirtAndDressWrittenAndReadBackAreTheSameCloth) {
    for (const GarmentType type : {GarmentType::skirt, GarmentType::dress}) {
        SCOPED_TRACE(garment_type_name(type));
        auto reference = build_world(put_on(built_in(type)), {});
        ASSERT_TRUE(reference) << reference.error().message;
        const fs::path file = dir / (std::string(garment_type_name(type)) + (type == GarmentType::skirt ? ".gltf" : ".glb"));
        ASSERT_TRUE(write_garment_mesh(file, garment_as_mesh(reference->registry, reference->garments.at(0))));
        auto world = build_world(put_on(from_file(file)), {});
        ASSERT_TRUE(world) << world.error().message;

        const Garment& a = reference->registry.get<Garment>(reference->garments.at(0));
        const Garment& b = world->registry.get<Garment>(world->garments.at(0));
        ASSERT_EQ(a.fabric->warp_lines, b.fabric->warp_lines);
        ASSERT_EQ(a.fabric->particles_per_line, b.fabric->particles_per_line);
        EXPECT_EQ(a.fabric->weft_stride, b.fabric->weft_stride);
        EXPECT_TRUE(b.fabric->closed);
        EXPECT_EQ(a.state.pins.size(), b.state.pins.size());
        EXPECT_EQ(a.body.colliders, b.body.colliders);
        EXPECT_EQ(a.body.anchor, b.body.anchor);
        Real farthest = 0;
        for (std::uint32_t line = 0; line < a.fabric->warp_lines; ++line)
            for (std::uint32_t row = 0; row < a.fabric->particles_per_line; ++row)
                farthest = std::max(farthest, (at(a, line, row) - at(b, line, row)).norm());
        EXPECT_LT(farthest, Real(1e-6)) << "particle for particle (the acceptance asks 1 mm)";
        EXPECT_EQ(a.config.material, b.config.material);
        EXPECT_EQ(a.config.model, b.config.model);
        EXPECT_EQ(a.config.inertia, b.config.inertia);
        for (std::size_t k = 0; k < a.state.pins.size(); ++k) EXPECT_EQ(a.state.pins[k].particle, b.state.pins[k].particle);

        // The same cloth: every spring's rest length and every particle's mass; and it walks
        // the same second.
        for (const auto phase : {&Fabric::warp1, &Fabric::warp2, &Fabric::weft}) {
            const SpringPhase& pa = (*a.fabric).*phase;
            const SpringPhase& pb = (*b.fabric).*phase;
            ASSERT_EQ(pa.size(), pb.size());
            EXPECT_EQ(pa.a, pb.a);
            EXPECT_EQ(pa.b, pb.b);
            for (std::size_t k = 0; k < pa.size(); ++k) EXPECT_NEAR(pa.rest_m[k], pb.rest_m[k], Real(1e-6)) << "spring " << k;
        }
        EXPECT_LT((a.state.inv_mass - b.state.inv_mass).cwiseAbs().maxCoeff(), a.state.inv_mass.maxCoeff() * Real(1e-5));
        for (int frame = 0; frame < 60; ++frame) {
            ASSERT_TRUE(step_world(*reference, 1.0 / 60.0));
            ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        }
        farthest = 0;
        for (std::uint32_t line = 0; line < a.fabric->warp_lines; ++line)
            for (std::uint32_t row = 0; row < a.fabric->particles_per_line; ++row)
                farthest = std::max(farthest, (at(a, line, row) - at(b, line, row)).norm());
        EXPECT_LT(farthest, Real(1e-6)) << "after a second of walking";
    }
}

TEST_F(GarmentFile, PinsArePaintedOrTheUpperEdge) {
    GarmentMeshAsset mesh = exported(GarmentType::skirt);
    ASSERT_GT(mesh.vertex_count(), 0u);
    MeshGarmentParams params;
    auto painted = grid_from_mesh(mesh, params, "garment");
    ASSERT_TRUE(painted) << painted.error().message;
    const int lines = painted->grid.warp_lines, rows = painted->grid.particles_per_line;
    EXPECT_EQ(std::count(painted->grid.pinned.begin(), painted->grid.pinned.end(), 1), lines);  // the skirt's one fitting row

    // Painted on a band of three rows instead.
    for (Eigen::Index v = 0; v < mesh.positions.cols(); ++v) mesh.pin[v] = mesh.uvs(1, v) < Real(2.5) / Real(rows - 1) ? 1 : 0;
    auto band = grid_from_mesh(mesh, params, "garment");
    ASSERT_TRUE(band) << band.error().message;
    EXPECT_EQ(std::count(band->grid.pinned.begin(), band->grid.pinned.end(), 1), 3 * lines);
    EXPECT_NE(band->how.find("painted"), std::string::npos) << band->how;

    // Automatic: the higher edge, whatever is painted; the rows turned so that it is row 0.
    params.pins = PinSource::automatic;
    params.fitting_rows = 2;
    Matrix2X upside_down = mesh.uvs;
    upside_down.row(1) = Eigen::RowVectorXf::Ones(mesh.uvs.cols()) - mesh.uvs.row(1);
    GarmentMeshAsset turned = mesh;
    turned.uvs = upside_down;
    auto automatic = grid_from_mesh(turned, params, "garment");
    ASSERT_TRUE(automatic) << automatic.error().message;
    EXPECT_EQ(std::count(automatic->grid.pinned.begin(), automatic->grid.pinned.end(), 1), 2 * lines);
    for (int line = 0; line < lines; ++line)
        EXPECT_GT(automatic->grid.grid_positions(1, line * rows), automatic->grid.grid_positions(1, line * rows + rows - 1));

    // Painted asked of a mesh without paint; paint that holds nothing.
    params.pins = PinSource::painted;
    GarmentMeshAsset unpainted = mesh;
    unpainted.pin.resize(0);
    auto none = grid_from_mesh(unpainted, params, "garment");
    ASSERT_FALSE(none);
    EXPECT_NE(none.error().message.find("garment.pins: mesh 'Garment' paints no pins (no COLOR_0)"), std::string::npos) << none.error().message;
    GarmentMeshAsset blank = mesh;
    blank.pin.setZero();
    auto nothing = grid_from_mesh(blank, params, "garment");
    ASSERT_FALSE(nothing);
    EXPECT_NE(nothing.error().message.find("paints no vertex held"), std::string::npos) << nothing.error().message;
}

// The one C++ call (docs/garments.md, "From C++"): a file's garment on a character already in
// a world, in denim; it then walks with the world.
TEST_F(GarmentFile, OneCallAttachesAFilesGarmentToACharacter) {
    const fs::path file = dir / "skirt.gltf";
    ASSERT_TRUE(write_garment_mesh(file, exported(GarmentType::skirt)));
    SceneDescription scene = sample_scene();
    scene.garments.clear();
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    MeshGarmentParams params;
    params.config.material = *material_preset("denim");
    auto skirt = attach_garment_file(world->registry, world->characters.at(0), file, "", params);
    ASSERT_TRUE(skirt) << skirt.error().message;
    const Garment& g = world->registry.get<Garment>(*skirt);
    EXPECT_EQ(g.fabric->particle_count(), 837u);
    EXPECT_EQ(g.state.pins.size(), 27u);
    EXPECT_EQ(g.config.material, *material_preset("denim"));
    const Matrix3X start = g.state.x;
    for (int frame = 0; frame < 30; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    EXPECT_TRUE(g.state.x.allFinite());
    EXPECT_GT((g.state.x - start).colwise().norm().maxCoeff(), Real(0.01)) << "the cloth system steps it";
    auto missing = attach_garment_file(world->registry, world->characters.at(0), dir / "none.glb");
    ASSERT_FALSE(missing);
    EXPECT_EQ(missing.error().message, (dir / "none.glb").string() + ": no such file");
}

// A print in four quadrants, 8 x 8 pixels (top row first): green, blue above; yellow, white
// below.
Image quadrants() {
    Image image;
    image.width = image.height = 8;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            const bool right = x >= 4, below = y >= 4;
            const std::uint8_t c[4][3] = {{30, 200, 40}, {30, 40, 220}, {230, 210, 20}, {250, 250, 250}};
            const auto& q = c[(below ? 2 : 0) + (right ? 1 : 0)];
            image.rgba.insert(image.rgba.end(), {q[0], q[1], q[2], 255});
        }
    return image;
}

// The base-colour texture: written into a .glb and read back pixel for pixel; read from an
// OBJ's material, a PNG beside it; carried to the garment's surface; a texture that is
// missing or not an image refused with one line naming the texture.
TEST_F(GarmentFile, ABaseColourTextureIsReadWrittenAndCarriedToTheSurface) {
    GarmentMeshAsset skirt = exported(GarmentType::skirt);
    ASSERT_GT(skirt.uvs.cols(), 0);
    skirt.base_color = quadrants();
    const fs::path glb = dir / "printed.glb";
    ASSERT_TRUE(write_garment_mesh(glb, skirt));
    auto back = import_garment_mesh(glb);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->base_color.width, 8);
    EXPECT_EQ(back->base_color.height, 8);
    EXPECT_EQ(back->base_color.rgba, skirt.base_color.rgba);
    // Carried to the surface the garment is drawn as.
    SceneDescription scene = put_on(from_file(glb));
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    const auto* surface = world->registry.try_get<GarmentSurface>(world->garments.at(0));
    ASSERT_NE(surface, nullptr);
    ASSERT_TRUE(surface->base_color);
    EXPECT_EQ(surface->base_color->rgba, skirt.base_color.rgba);
    EXPECT_EQ(surface->uvs.cols(), static_cast<Eigen::Index>(surface->carriers.size()));
    // Untextured without a texture.
    GarmentMeshAsset plain = skirt;
    plain.base_color = {};
    ASSERT_TRUE(write_garment_mesh(dir / "plain.glb", plain));
    auto plain_back = import_garment_mesh(dir / "plain.glb");
    ASSERT_TRUE(plain_back) << plain_back.error().message;
    EXPECT_TRUE(plain_back->base_color.empty());

    // An OBJ whose material's diffuse map is a PNG beside it.
    {
        std::ofstream obj(dir / "square.obj");
        obj << "mtllib square.mtl\nv 0 1 0\nv 1 1 0\nv 1 0 0\nv 0 0 0\nvt 0 1\nvt 1 1\nvt 1 0\nvt 0 0\nusemtl print\nf 1/1 4/4 3/3\nf 1/1 3/3 2/2\n";
        std::ofstream mtl(dir / "square.mtl");
        mtl << "newmtl print\nKd 1 1 1\nmap_Kd print.png\n";
    }
    const Image print = quadrants();
    ASSERT_NE(stbi_write_png((dir / "print.png").c_str(), 8, 8, 4, print.rgba.data(), 8 * 4), 0);
    auto square = import_garment_mesh(dir / "square.obj");
    ASSERT_TRUE(square) << square.error().message;
    EXPECT_EQ(square->base_color.rgba, quadrants().rgba);
    // Missing, then not an image.
    fs::remove(dir / "print.png");
    auto missing = import_garment_mesh(dir / "square.obj");
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().message.find("base-colour texture 'print.png': no such file " + (dir / "print.png").string()), std::string::npos)
        << missing.error().message;
    std::ofstream(dir / "print.png") << "not a picture";
    auto garbage = import_garment_mesh(dir / "square.obj");
    ASSERT_FALSE(garbage);
    EXPECT_NE(garbage.error().message.find("square.obj"), std::string::npos) << garbage.error().message;
    EXPECT_NE(garbage.error().message.find("not a PNG or JPEG image"), std::string::npos) << garbage.error().message;
    // A BMP under the PNG's name: stb's library reads it, the docs promise PNG and JPEG only.
    ASSERT_NE(stbi_write_bmp((dir / "print.png").c_str(), 8, 8, 4, print.rgba.data()), 0);
    auto bitmap = import_garment_mesh(dir / "square.obj");
    ASSERT_FALSE(bitmap);
    EXPECT_NE(bitmap.error().message.find("not a PNG or JPEG image"), std::string::npos) << bitmap.error().message;
}

// A garment an artist modelled on the character's bind pose (as in Blender) is placed on the
// pose it is put on in by the skin weights of the trunk. Posed by one rigid motion of every
// bone, the skirt cut for the walk moves with it exactly; with only the limbs moved, it stays
// (a skirt between the legs is carried by the hips, not pulled apart by the thighs).
TEST_F(GarmentFile, AGarmentModelledOnTheBindPoseIsCarriedByTheTrunk) {
    auto cut = cut_garments(sample_scene());
    ASSERT_TRUE(cut) << cut.error().message;
    const GarmentMeshAsset& skirt = cut->front().mesh;
    SceneDescription scene = sample_scene();
    scene.garments.clear();
    scene.solver.settle_s = 0;
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    const Entity body = world->characters.at(0);
    Skeleton& skeleton = world->registry.get<Skeleton>(body);
    const std::vector<Affine3> walking = skeleton.skinning;

    Affine3 rigid = Affine3::Identity();
    rigid.rotate(Eigen::AngleAxis<Real>(Real(0.5), Vec3::UnitY()));
    rigid.pretranslate(Vec3(0.1f, 0.02f, -0.05f));
    std::fill(skeleton.skinning.begin(), skeleton.skinning.end(), rigid);
    GarmentMeshAsset placed = skirt;
    auto how = place_on_current_pose(world->registry, body, GarmentPose::bind, placed, "garments[0]");
    ASSERT_TRUE(how) << how.error().message;
    EXPECT_NE(how->find("modelled on the bind pose"), std::string::npos) << *how;
    EXPECT_LT((placed.positions - rigid * skirt.positions).cwiseAbs().maxCoeff(), Real(1e-4));

    // The limbs swung a quarter turn, the trunk where it was bound.
    const auto& landmarks = world->registry.get<BodyLandmarks>(body);
    const SkeletonAsset& bones = *skeleton.asset;
    std::vector<char> limb(bones.size(), 0);
    for (const LimbChain* chain : {&landmarks.left_leg, &landmarks.right_leg, &landmarks.left_arm, &landmarks.right_arm}) {
        ASSERT_GE(chain->root, 0);
        limb[static_cast<std::size_t>(chain->root)] = 1;
    }
    for (std::size_t b = 0; b < bones.size(); ++b) {
        if (bones.parents[b] >= 0 && limb[static_cast<std::size_t>(bones.parents[b])]) limb[b] = 1;
        skeleton.skinning[b] = limb[b] ? Affine3(Eigen::AngleAxis<Real>(Real(1.57), Vec3::UnitX())) : Affine3::Identity();
    }
    GarmentMeshAsset kept = skirt;
    ASSERT_TRUE(place_on_current_pose(world->registry, body, GarmentPose::bind, kept, "garments[0]"));
    EXPECT_LT((kept.positions - skirt.positions).cwiseAbs().maxCoeff(), Real(1e-5));
    skeleton.skinning = walking;

    // As it stands: left where it is.
    GarmentMeshAsset posed = skirt;
    auto left = place_on_current_pose(world->registry, body, GarmentPose::current, posed, "garments[0]");
    ASSERT_TRUE(left) << left.error().message;
    EXPECT_EQ((posed.positions - skirt.positions).cwiseAbs().maxCoeff(), 0);

    // From a scene file: the field read, the garment placed and walking.
    const fs::path scene_file = dir / "bind.json";
    std::ofstream(scene_file) << R"({"characters": [{"file": ")" << (test::source_dir() / "assets" / "avatar.glb").string()
                              << R"("}], "garments": [{"file": ")" << (test::source_dir() / "assets" / "garments" / "flared_skirt.glb").string()
                              << R"(", "modelled_on": "bind"}]})";
    auto loaded = load_scene_file(scene_file);
    ASSERT_TRUE(loaded) << loaded.error().message;
    ASSERT_EQ(loaded->garments.at(0).modelled_on, GarmentPose::bind);
    auto worn = build_world(*loaded, {});
    ASSERT_TRUE(worn) << worn.error().message;
    for (int frame = 0; frame < 30; ++frame) ASSERT_TRUE(step_world(*worn, 1.0 / 60.0));
    EXPECT_TRUE(worn->registry.get<Garment>(worn->garments.at(0)).state.x.allFinite());
    std::ofstream(scene_file) << R"({"characters": [{"file": ")" << (test::source_dir() / "assets" / "avatar.glb").string()
                              << R"("}], "garments": [{"file": ")" << (test::source_dir() / "assets" / "garments" / "flared_skirt.glb").string()
                              << R"(", "modelled_on": "sideways"}]})";
    auto bad = load_scene_file(scene_file);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("garments[0].modelled_on"), std::string::npos) << bad.error().message;

    // Asked of a body without skin: one line naming the field.
    const Entity bare = world->registry.create();
    GarmentMeshAsset nowhere = skirt;
    auto refused = place_on_current_pose(world->registry, bare, GarmentPose::bind, nowhere, "garments[0]");
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().message, "garments[0].modelled_on: the character has no skin and skeleton to place a bind-pose garment by");
}

// Three flat panels side by side, listed middle first and the right one's pattern turned: one
// open grid across all three, its lines evenly spaced over the seams.
TEST(GarmentPanels, PanelsAreSewnSideBySideInWhateverOrderAndTurnTheyCome) {
    GarmentMeshAsset mesh;
    std::vector<Vec3> xs;
    std::vector<Eigen::Vector2f> uvs;
    const auto panel = [&](Real x0, Real u0, bool turned) {
        const auto first = static_cast<std::uint32_t>(xs.size());
        constexpr int across = 6, down = 10;
        for (int j = 0; j <= down; ++j)
            for (int i = 0; i <= across; ++i) {
                const Real s = Real(i) / across, t = Real(j) / down;
                xs.emplace_back(x0 + Real(0.3) * s, Real(1.0) - Real(0.5) * t, Real(0.2));
                uvs.emplace_back(u0 + Real(0.15) * (turned ? 1 - s : s), Real(0.25) * t);
            }
        for (int j = 0; j < down; ++j)
            for (int i = 0; i < across; ++i) {
                const auto a = first + static_cast<std::uint32_t>(j * (across + 1) + i);
                mesh.indices.insert(mesh.indices.end(), {a, a + across + 1, a + 1, a + 1, a + across + 1, a + across + 2});
            }
    };
    panel(Real(0.3), Real(0.2), false);  // middle
    panel(Real(0.0), Real(0.0), false);  // left
    panel(Real(0.6), Real(0.4), true);   // right, its pattern turned
    mesh.positions.resize(3, static_cast<Eigen::Index>(xs.size()));
    mesh.uvs.resize(2, static_cast<Eigen::Index>(xs.size()));
    for (std::size_t k = 0; k < xs.size(); ++k) {
        mesh.positions.col(static_cast<Eigen::Index>(k)) = xs[k];
        mesh.uvs.col(static_cast<Eigen::Index>(k)) = uvs[k];
    }
    MeshGarmentParams params;
    params.spacing_m = Real(0.05);
    auto grid = grid_from_mesh(mesh, params, "sheet");
    ASSERT_TRUE(grid) << grid.error().message;
    const GridGarment& g = grid->grid;
    EXPECT_FALSE(g.closed);
    EXPECT_EQ(g.warp_lines, 3 * 6 + 1) << grid->how;  // 0.3 m at 0.05 m: 6 segments a panel
    const int m = g.particles_per_line;
    for (int line = 0; line < g.warp_lines; ++line)  // row 0 (held, the higher edge) evenly across 0..0.9 m
        EXPECT_NEAR(std::min(g.grid_positions(0, line * m), Real(0.9) - g.grid_positions(0, line * m)),
                    std::min(Real(0.05) * Real(line), Real(0.9) - Real(0.05) * Real(line)), Real(1e-4)) << "line " << line;
    EXPECT_NE(grid->how.find("from 3 panels sewn at 2 seams, open"), std::string::npos) << grid->how;
}

// A file that paints no pins is held at its higher edge, and the world says so in one line.
TEST_F(GarmentFile, AFileWithoutPinsIsHeldAtItsUpperEdgeAndSaysSo) {
    GarmentMeshAsset mesh = exported(GarmentType::skirt);
    ASSERT_GT(mesh.vertex_count(), 0u);
    mesh.pin.resize(0);
    const fs::path file = dir / "unpainted.glb";
    ASSERT_TRUE(write_garment_mesh(file, mesh));
    auto world = build_world(put_on(from_file(file)), {});
    ASSERT_TRUE(world) << world.error().message;
    const Garment& g = world->registry.get<Garment>(world->garments.at(0));
    EXPECT_EQ(g.state.pins.size(), g.fabric->warp_lines);
    for (const PinBinding& pin : g.state.pins) EXPECT_NEAR(g.state.x(1, pin.particle), g.state.x.row(1).maxCoeff(), Real(0.03));
    ASSERT_EQ(world->warnings.size(), 1u);
    EXPECT_EQ(world->warnings[0], "garments[0]: " + file.string() + " paints no pins (COLOR_0): held at its higher edge, 1 row");
}

// A finer grid than the file's own lattice: the lines and rows lie on the file's surface, the
// skirt walks within the contract.
// Labelled `figures`: the short form walks 36 frames and asserts that they run clean.
TEST_F(GarmentFile, AMeshResampledAtAFinerSpacingLiesOnItsSurfaceAndWalks) {
    const GarmentMeshAsset mesh = exported(GarmentType::skirt);
    ASSERT_GT(mesh.vertex_count(), 0u);
    MeshGarmentParams params;
    params.spacing_m = Real(0.015);
    auto grid = grid_from_mesh(mesh, params, "garment");
    ASSERT_TRUE(grid) << grid.error().message;
    auto lattice = grid_from_mesh(mesh, MeshGarmentParams{}, "garment");
    ASSERT_TRUE(lattice);
    EXPECT_GT(grid->grid.warp_lines, lattice->grid.warp_lines);
    EXPECT_GT(grid->grid.particles_per_line, lattice->grid.particles_per_line);
    EXPECT_EQ(grid->grid.warp_lines % 3, 0);
    EXPECT_TRUE(grid->grid.closed);
    EXPECT_NE(grid->how.find("resampled"), std::string::npos) << grid->how;
    // Each grid point on one of the mesh's triangles (within 0.1 mm of its plane and inside it).
    const auto on_surface = [&](const Vec3& p) {
        for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
            const Vec3 a = mesh.positions.col(mesh.indices[t]), b = mesh.positions.col(mesh.indices[t + 1]),
                       c = mesh.positions.col(mesh.indices[t + 2]);
            const Vec3 n = (b - a).cross(c - a).normalized();
            const Vec3 q = p - n * n.dot(p - a);
            if (std::abs(n.dot(p - a)) > Real(1e-4)) continue;
            const Real area = (b - a).cross(c - a).norm();
            const Real sum = (b - q).cross(c - q).norm() + (c - q).cross(a - q).norm() + (a - q).cross(b - q).norm();
            if (sum <= area * Real(1.001)) return true;
        }
        return false;
    };
    int off = 0;
    for (Eigen::Index k = 0; k < grid->grid.grid_positions.cols(); ++k) off += !on_surface(grid->grid.grid_positions.col(k));
    EXPECT_EQ(off, 0);

    const fs::path file = dir / "skirt.glb";
    ASSERT_TRUE(write_garment_mesh(file, mesh));
    GarmentDescription g = from_file(file);
    g.spacing_m = 0.015;
    SceneDescription scene = sample_scene();
    scene.garments = {g};
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    for (int frame = 0; frame < test::frames(180); ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    const GarmentStats stats = run_stats(*world).garments.at(0);
    EXPECT_EQ(stats.nonfinite, 0u);
    if (test::short_form()) return;
    EXPECT_TRUE(contract_breaches(stats).empty()) << garment_verdict("skirt", stats);
}

// A mesh without UVs (an OBJ straight from a sculpt): its pattern is derived round the
// vertical axis, the tube cut at a seam, and it is gridded like the file with UVs, its grid
// points on its surface; put on, it says so in one line and walks within the contract. Seen
// from its axis, a mesh folding back over itself (a hem turned up inside) is refused.
// Labelled `figures`: the short form walks 36 frames and asserts that they run clean.
TEST_F(GarmentFile, AMeshWithoutUVsIsGriddedRoundItsAxisAndWalks) {
    GarmentMeshAsset mesh = exported(GarmentType::skirt);
    ASSERT_GT(mesh.vertex_count(), 0u);
    mesh.uvs.resize(2, 0);
    mesh.pin.resize(0);
    // Welded as a modeller keeps a tube: the pattern's seam (its first line written twice) closed.
    for (std::uint32_t& i : mesh.indices)
        for (std::uint32_t j = 0; j < i; ++j)
            if (mesh.positions.col(j) == mesh.positions.col(i)) {
                i = j;
                break;
            }
    GarmentMeshAsset derived = mesh;
    auto line = derive_pattern(derived, "garment");
    ASSERT_TRUE(line) << line.error().message;
    EXPECT_NE(line->find("cut at a seam"), std::string::npos) << *line;
    EXPECT_GT(derived.vertex_count(), mesh.vertex_count());  // the seam's vertices, doubled
    EXPECT_EQ(derived.uvs.cols(), derived.positions.cols());
    auto grid = grid_from_mesh(derived, {}, "garment");
    ASSERT_TRUE(grid) << grid.error().message;
    EXPECT_TRUE(grid->grid.closed) << grid->how;
    EXPECT_NE(grid->how.find("1 panel sewn at 1 seam, closed"), std::string::npos) << grid->how;
    // The built-in skirt's 0.029 m lines and rows: as many, give or take a stride of lines.
    MeshGarmentParams resampled;
    resampled.spacing_m = Real(0.029);
    auto with_uvs = grid_from_mesh(exported(GarmentType::skirt), resampled, "garment");
    ASSERT_TRUE(with_uvs) << with_uvs.error().message;
    EXPECT_NEAR(grid->grid.warp_lines, with_uvs->grid.warp_lines, 3);
    EXPECT_NEAR(grid->grid.particles_per_line, with_uvs->grid.particles_per_line, 2);
    // Every grid point within 0.1 mm of the mesh's surface.
    const auto distance = [&](const Vec3& p) {
        Real best = std::numeric_limits<Real>::infinity();
        for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
            const Vec3 a = mesh.positions.col(mesh.indices[t]), b = mesh.positions.col(mesh.indices[t + 1]),
                       c = mesh.positions.col(mesh.indices[t + 2]);
            const Vec3 n = (b - a).cross(c - a).normalized();
            const Vec3 q = p - n * n.dot(p - a);
            const Real area = (b - a).cross(c - a).norm();
            const Real sum = (b - q).cross(c - q).norm() + (c - q).cross(a - q).norm() + (a - q).cross(b - q).norm();
            if (sum <= area * Real(1.001)) best = std::min(best, std::abs(n.dot(p - a)));
        }
        return best;
    };
    Real farthest = 0;
    for (Eigen::Index k = 0; k < grid->grid.grid_positions.cols(); ++k) farthest = std::max(farthest, distance(grid->grid.grid_positions.col(k)));
    EXPECT_LT(farthest, Real(1e-4));

    // Open at the back (its triangles within 30 degrees of -z taken out, a wrap skirt's
    // opening): no seam is cut, the pattern opens there and the grid is open.
    GarmentMeshAsset open = mesh;
    const Vec3 centre = mesh.positions.rowwise().mean();
    std::vector<std::uint32_t> kept;
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        bool back = false;
        for (std::size_t k = 0; k < 3; ++k) {
            const Vec3 d = mesh.positions.col(mesh.indices[t + k]) - centre;
            back = back || std::abs(std::atan2(d.x(), -d.z())) * 180 / std::numbers::pi_v<Real> < 15;
        }
        if (!back) kept.insert(kept.end(), mesh.indices.begin() + static_cast<std::ptrdiff_t>(t), mesh.indices.begin() + static_cast<std::ptrdiff_t>(t) + 3);
    }
    open.indices = kept;
    auto open_line = derive_pattern(open, "garment");
    ASSERT_TRUE(open_line) << open_line.error().message;
    EXPECT_NE(open_line->find("open where its widest gap round the axis is"), std::string::npos) << *open_line;
    EXPECT_EQ(open.vertex_count(), mesh.vertex_count());
    auto open_grid = grid_from_mesh(open, {}, "garment");
    ASSERT_TRUE(open_grid) << open_grid.error().message;
    EXPECT_FALSE(open_grid->grid.closed) << open_grid->how;

    GarmentMeshAsset folded = mesh;  // the lower half turned up inside the upper
    const Real mid = (folded.positions.row(1).minCoeff() + folded.positions.row(1).maxCoeff()) / 2;
    for (Eigen::Index v = 0; v < folded.positions.cols(); ++v)
        if (folded.positions(1, v) < mid) folded.positions(1, v) = 2 * mid - folded.positions(1, v), folded.positions.col(v).x() *= Real(0.98);
    GarmentMeshAsset past = mesh;  // a triangle on a vertex the mesh does not have
    past.indices[0] = static_cast<std::uint32_t>(past.vertex_count()) + 7;
    auto bad = derive_pattern(past, "garments[0]");
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("garments[0]: mesh 'Garment' has a triangle on vertex"), std::string::npos) << bad.error().message;
    auto refused = derive_pattern(folded, "garments[0]");
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("garments[0]: mesh 'Garment' has no UVs, and no pattern can be derived: seen from its vertical "
                                           "axis"),
              std::string::npos)
        << refused.error().message;

    const fs::path file = dir / "no_uvs.glb";
    ASSERT_TRUE(write_garment_mesh(file, mesh));
    SceneDescription scene = sample_scene();
    scene.garments = {from_file(file)};
    auto world = build_world(scene, {});
    ASSERT_TRUE(world) << world.error().message;
    bool said = false;
    for (const std::string& w : world->warnings)
        said = said || w == "garments[0]: " + file.string() + ": " + *line;
    EXPECT_TRUE(said) << (world->warnings.empty() ? "no warnings" : world->warnings.back());
    for (int frame = 0; frame < test::frames(180); ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
    const GarmentStats stats = run_stats(*world).garments.at(0);
    EXPECT_EQ(stats.nonfinite, 0u);
    if (test::short_form()) return;
    EXPECT_TRUE(contract_breaches(stats).empty()) << garment_verdict("skirt", stats);
}

TEST_F(GarmentFile, BadFilesAndFieldsGetOneLineNamingThem) {
    const auto message = [](const auto& result) { return result ? std::string("(no error)") : result.error().message; };
    EXPECT_EQ(message(import_garment_mesh(dir / "missing.glb")), (dir / "missing.glb").string() + ": no such file");
    const fs::path text = dir / "notes.gltf";
    std::ofstream(text) << "not a model";
    EXPECT_NE(message(import_garment_mesh(text)).find("notes.gltf: not a readable model"), std::string::npos);

    GarmentMeshAsset mesh = exported(GarmentType::skirt);
    ASSERT_GT(mesh.vertex_count(), 0u);
    const fs::path file = dir / "skirt.gltf";
    ASSERT_TRUE(write_garment_mesh(file, mesh));
    EXPECT_EQ(message(write_garment_mesh(file, mesh)), file.string() + ": exists (not overwritten)");
    EXPECT_NE(message(write_garment_mesh(dir / "skirt.obj", mesh)).find("name the file .gltf or .glb"), std::string::npos);
    EXPECT_NE(message(import_garment_mesh(file, "Belt")).find("no mesh named 'Belt' (meshes: Garment)"), std::string::npos);
    auto named = import_garment_mesh(file, "Garment");
    ASSERT_TRUE(named) << named.error().message;
    EXPECT_EQ(named->vertex_count(), mesh.vertex_count());
    EXPECT_EQ(split_garment_reference(file.string() + ":Garment"), std::pair(file, std::string("Garment")));
    EXPECT_EQ(split_garment_reference(file.string()), std::pair(file, std::string()));

    GarmentMeshAsset no_uvs = mesh;
    no_uvs.uvs.resize(2, 0);
    EXPECT_NE(message(grid_from_mesh(no_uvs, {}, "garments[0]")).find("garments[0]: mesh 'Garment' has no UV coordinates"), std::string::npos);
    GarmentMeshAsset two = mesh;  // a second, separate copy beside the first
    const auto n = static_cast<std::uint32_t>(mesh.vertex_count());
    two.positions.conservativeResize(3, 2 * n);
    two.positions.rightCols(n) = mesh.positions.colwise() + Vec3(1, 0, 0);
    two.uvs.conservativeResize(2, 2 * n);
    two.uvs.rightCols(n) = mesh.uvs;
    two.pin.conservativeResize(2 * n);
    two.pin.tail(n) = mesh.pin;
    for (std::uint32_t i : mesh.indices) two.indices.push_back(i + n);
    EXPECT_NE(message(grid_from_mesh(two, {}, "garments[0]")).find("has 2 panels, but only 1 join side by side"), std::string::npos)
        << message(grid_from_mesh(two, {}, "garments[0]"));
    GarmentMeshAsset slit = mesh;  // a slit up the front: a level of v crosses the panel twice
    std::vector<std::uint32_t> kept;
    for (std::size_t t = 0; t + 2 < slit.indices.size(); t += 3) {
        Real u = 0, v = 0;
        for (std::size_t k = 0; k < 3; ++k) u += slit.uvs(0, slit.indices[t + k]) / 3, v += slit.uvs(1, slit.indices[t + k]) / 3;
        if (std::abs(u - Real(0.5)) < Real(0.05) && v > Real(0.5)) continue;
        kept.insert(kept.end(), slit.indices.begin() + static_cast<std::ptrdiff_t>(t), slit.indices.begin() + static_cast<std::ptrdiff_t>(t) + 3);
    }
    slit.indices = kept;
    MeshGarmentParams spaced;
    spaced.spacing_m = Real(0.03);
    EXPECT_NE(message(grid_from_mesh(slit, spaced, "garments[0]")).find("fall outside it: a panel must be one piece across"),
              std::string::npos) << message(grid_from_mesh(slit, spaced, "garments[0]"));

    // Another unit than the character's (centimetres against metres, and back): one line.
    for (const Real scale : {Real(100), Real(0.01)}) {
        GarmentMeshAsset scaled = mesh;
        scaled.positions *= scale;
        const fs::path scaled_file = dir / (scale > 1 ? "skirt_cm.gltf" : "skirt_hm.gltf");
        ASSERT_TRUE(write_garment_mesh(scaled_file, scaled));
        auto refused = build_world(put_on(from_file(scaled_file)), {});
        ASSERT_FALSE(refused) << scale;
        EXPECT_NE(refused.error().message.find("garments[0]: mesh 'Garment' spans "), std::string::npos) << refused.error().message;
        EXPECT_NE(refused.error().message.find("not in the character's units"), std::string::npos) << refused.error().message;
    }
    // Placed wrong on the body: beside it, shrunk into it, or held far round it: one line.
    Vec3 held = Vec3::Zero();
    Real held_count = 0;
    for (Eigen::Index v = 0; v < mesh.positions.cols(); ++v)
        if (mesh.pin[v] >= Real(0.5)) held += mesh.positions.col(v), held_count += 1;
    ASSERT_GT(held_count, 0);
    held /= held_count;
    const struct {
        const char* file;
        Vec3 scale;
        Vec3 offset;
        const char* reason;
    } misplaced[] = {
        {"beside.gltf", Vec3::Ones(), Vec3(Real(0.8), 0, 0), "is closed round, but its held edge does not go round the body (0.00 turns"},
        {"inside.gltf", Vec3::Constant(Real(0.3)), Vec3::Zero(), "lies inside the body ("},
        {"wide.gltf", Vec3(3, 1, 3), Vec3::Zero(), "m from the body (the median of its held points; at most 10 % of the character's height"},
    };
    for (const auto& wrong : misplaced) {
        GarmentMeshAsset moved = mesh;
        moved.positions = ((moved.positions.colwise() - held).array().colwise() * wrong.scale.array()).matrix().colwise() + (held + wrong.offset);
        ASSERT_TRUE(write_garment_mesh(dir / wrong.file, moved));
        auto refused = build_world(put_on(from_file(dir / wrong.file)), {});
        ASSERT_FALSE(refused) << wrong.file;
        EXPECT_TRUE(refused.error().message.starts_with("garments[0]: mesh 'Garment' ")) << refused.error().message;
        EXPECT_NE(refused.error().message.find(wrong.reason), std::string::npos) << refused.error().message;
    }
    EXPECT_TRUE(check_garment_units(mesh, Real(1.75), "g"));
    GarmentMeshAsset tall = mesh;
    tall.positions *= Real(20);
    EXPECT_FALSE(check_garment_units(tall, Real(1.75), "g"));
    EXPECT_TRUE(check_garment_units(tall, Real(0), "g")) << "no height: no check";

    // Scene fields.
    // The parameter table says which parameters a garment from a file takes (a scene's
    // "file" column); each of the others is refused by name.
    for (const GarmentParameterSpec& spec : garment_parameters()) {
        GarmentDescription shaped = from_file(file);
        shaped.parameters.push_back({std::string(spec.name), spec.get(TubeParams::skirt())});
        auto world = build_world(put_on(shaped), {});
        if (spec.takes_file_garments()) {
            EXPECT_TRUE(world) << spec.name << ": " << world.error().message;
        } else {
            ASSERT_FALSE(world) << spec.name;
            EXPECT_NE(world.error().message.find(std::string(spec.name) + ": shapes a built-in garment"), std::string::npos)
                << world.error().message;
        }
    }
    GarmentDescription cloth = from_file(file);
    cloth.material = "denim";
    cloth.parameters.push_back({"fitting_rows", 2});
    auto denim = build_world(put_on(cloth), {});
    ASSERT_TRUE(denim) << denim.error().message;
    // The file paints one row; fitting_rows applies to automatic pins only.
    const Garment& worn = denim->registry.get<Garment>(denim->garments.at(0));
    EXPECT_EQ(worn.state.pins.size(), worn.fabric->warp_lines);
    EXPECT_EQ(worn.config.material, *material_preset("denim"));

    const fs::path scene_file = dir / "scene.json";
    std::ofstream(scene_file) << R"({"characters": [{"file": ")" << sample_scene().characters.at(0).file.string()
                              << R"("}], "garments": [{"type": "skirt", "file": "skirt.gltf"}]})";
    auto both = load_scene_file(scene_file);
    ASSERT_FALSE(both);
    EXPECT_NE(both.error().message.find("give either type (a built-in garment) or file, not both"), std::string::npos)
        << both.error().message;
    std::ofstream(scene_file) << R"({"characters": [{"file": ")" << sample_scene().characters.at(0).file.string()
                              << R"("}], "garments": [{"spacing_m": 0.02}]})";
    auto stray = load_scene_file(scene_file);
    ASSERT_FALSE(stray);
    EXPECT_NE(stray.error().message.find("applies to a garment from a file"), std::string::npos) << stray.error().message;
    std::ofstream(scene_file) << R"({"characters": [{"file": ")" << sample_scene().characters.at(0).file.string()
                              << R"("}], "garments": [{"file": "skirt.gltf", "mesh": "Garment", "pins": "auto", "spacing_m": 0.025}]})";
    auto read = load_scene_file(scene_file);
    ASSERT_TRUE(read) << read.error().message;
    const GarmentDescription& g = read->garments.at(0);
    EXPECT_EQ(g.file, dir / "skirt.gltf");  // relative to the scene file
    EXPECT_EQ(g.mesh, "Garment");
    EXPECT_EQ(g.pins, PinSource::automatic);
    EXPECT_DOUBLE_EQ(g.spacing_m, 0.025);
}

}  // namespace
}  // namespace drape

namespace drape {
namespace {

// A mesh an exporter split into parts, one per material, under one name (an OBJ object
// with two materials here; FBX and glTF primitives alike) is read whole, its parts one
// after another; the file's other meshes are named beside it.
TEST_F(GarmentFile, AMeshSplitByMaterialIsReadWhole) {
    std::ofstream(dir / "two.mtl") << "newmtl Red\nKd 1 0 0\nnewmtl Blue\nKd 0 0 1\n";
    std::ofstream(dir / "two.obj") << "mtllib two.mtl\no Skirt\n"
                                      "v 0 1 0\nv 1 1 0\nv 0 0 0\nv 1 0 0\nv 2 1 0\nv 2 0 0\n"
                                      "vt 0 1\nvt 0.5 1\nvt 0 0\nvt 0.5 0\nvt 1 1\nvt 1 0\n"
                                      "usemtl Red\nf 1/1 3/3 2/2\nf 2/2 3/3 4/4\n"
                                      "usemtl Blue\nf 2/2 4/4 5/5\nf 5/5 4/4 6/6\n"
                                      "o Belt\nv 0 2 0\nv 1 2 0\nv 0 1.5 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 7/7 9/9 8/8\n";
    const fs::path file = dir / "two.obj";
    const auto both = import_garment_mesh(file);
    ASSERT_FALSE(both);
    EXPECT_EQ(both.error().message, file.string() + ": 2 meshes (Skirt (2 parts), Belt): name one as " + file.string() + ":MESH");
    const auto skirt = import_garment_mesh(file, "Skirt");
    ASSERT_TRUE(skirt) << skirt.error().message;
    EXPECT_EQ(skirt->name, "Skirt");
    EXPECT_EQ(skirt->indices.size(), 12u);  // both parts' triangles
    ASSERT_EQ(skirt->uvs.cols(), skirt->positions.cols());
    EXPECT_NEAR(skirt->positions.row(0).maxCoeff(), 2.0f, 1e-6f);  // the second part's far edge
    EXPECT_NEAR(skirt->uvs.row(0).maxCoeff(), 1.0f, 1e-6f);
    for (const std::uint32_t i : skirt->indices) EXPECT_LT(i, skirt->vertex_count());
    const auto belt = import_garment_mesh(file, "Belt");
    ASSERT_TRUE(belt) << belt.error().message;
    EXPECT_EQ(belt->indices.size(), 3u);
}

// Drawn as authored (components/garment_surface.hpp): each cut garment is drawn as its own
// mesh, not the simulation's grid. Placed on the grid where it was cut, the mesh is where
// the artist put it; after a walk the render system draws it, every vertex carried and
// finite.
TEST_F(GarmentFile, TheArtistsMeshIsDrawnCarriedByTheParticles) {
    auto cut = cut_garments(sample_scene());
    ASSERT_TRUE(cut) << cut.error().message;
    for (const CutGarment& c : *cut) {
        SCOPED_TRACE(c.name);
        const fs::path file = dir / (c.name + ".glb");
        ASSERT_TRUE(write_garment_mesh(file, c.mesh));
        auto world = build_world(put_on(from_file(file)), {});
        ASSERT_TRUE(world) << world.error().message;
        const Entity e = world->garments.at(0);
        const Garment& g = world->registry.get<Garment>(e);
        const auto* surface = world->registry.try_get<GarmentSurface>(e);
        ASSERT_NE(surface, nullptr);
        EXPECT_EQ(surface->triangles, c.mesh.indices);
        ASSERT_EQ(surface->carriers.size(), c.mesh.vertex_count());
        // On the cut grid (Fabric::rest_shape, in particle order) the mesh is where it was
        // modelled (the sample avatar stands at the origin: model space is world space).
        const Fabric& f = *g.fabric;
        Matrix3X rest(3, static_cast<Eigen::Index>(f.particle_count()));
        for (std::size_t k = 0; k < f.grid.size(); ++k) rest.col(f.grid[k]) = f.rest_shape.col(static_cast<Eigen::Index>(k));
        GarmentSurface placed = *surface;
        place_surface(placed, rest, f.triangles);
        const VectorX error = (placed.positions - c.mesh.positions).colwise().norm().transpose();
        std::vector<Real> sorted(error.data(), error.data() + error.size());
        std::sort(sorted.begin(), sorted.end());
        const Real p99 = sorted[sorted.size() * 99 / 100], worst = sorted.back();
        std::printf("%s: %zu vertices on a %u x %u grid; off the cut p99 %.2f mm, max %.2f mm\n", c.name.c_str(), sorted.size(),
                    f.warp_lines, f.particles_per_line, 1e3 * p99, 1e3 * worst);
        EXPECT_LT(p99, Real(1e-3));
        EXPECT_LT(worst, Real(2e-3));

        for (int frame = 0; frame < 60; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        place_garment_surfaces(world->registry);  // the garment surface system's run
        DrawList list;
        build_draw_list(world->registry, false, list);
        const auto draw = std::find_if(list.meshes.begin(), list.meshes.end(), [&](const MeshDraw& m) { return m.positions == &surface->positions; });
        ASSERT_NE(draw, list.meshes.end()) << "the garment is drawn as its grid";
        EXPECT_EQ(draw->triangles.size(), c.mesh.indices.size());
        EXPECT_EQ(draw->normals, &surface->normals);
        EXPECT_EQ(surface->positions.cols(), c.mesh.positions.cols());
        EXPECT_TRUE(surface->positions.allFinite());
        EXPECT_TRUE(surface->normals.allFinite());
    }
}

}  // namespace
}  // namespace drape
