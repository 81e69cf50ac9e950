// Characters as they come, made from the default avatar by the generator
// (game/avatar_generator.hpp) and changed as files from elsewhere are: its bones renamed
// to generic names, a base block under it and a prop at its feet, its units centimetres,
// a skirt modelled into the file. Each must get the unmodified avatar's landmarks, within
// 3 cm: the landmarks come from the skeleton's topology and the body's skin, names being a
// hint only, and the fit and the landmarks leave out what is not the body.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <assimp/Exporter.hpp>
#include <assimp/scene.h>

#include "drape/components/body_landmarks.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/transform.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/engine/assets/character_import.hpp"
#include "drape/game/avatar_generator.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/world.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/character_report.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

const AvatarModel& avatar() {
    static const AvatarModel model = make_default_avatar();
    return model;
}

fs::path temp_file(const std::string& name) { return test::binary_dir() / ("variant_" + name + ".glb"); }

// A box of triangles (12) between two corners, as an assimp mesh on material 0.
aiMesh* box(const char* name, const Vec3& lo, const Vec3& hi) {
    auto* mesh = new aiMesh();
    mesh->mName = aiString(name);
    mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    mesh->mNumVertices = 8;
    mesh->mVertices = new aiVector3D[8];
    mesh->mNormals = new aiVector3D[8];
    for (unsigned i = 0; i < 8; ++i) {
        const Vec3 p((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
        mesh->mVertices[i] = aiVector3D(p.x(), p.y(), p.z());
        const Vec3 n = (p - Real(0.5) * (lo + hi)).normalized();
        mesh->mNormals[i] = aiVector3D(n.x(), n.y(), n.z());
    }
    static const unsigned faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                                          {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    mesh->mNumFaces = 12;
    mesh->mFaces = new aiFace[12];
    for (unsigned f = 0; f < 12; ++f) {
        mesh->mFaces[f].mNumIndices = 3;
        mesh->mFaces[f].mIndices = new unsigned[3]{faces[f][0], faces[f][1], faces[f][2]};
    }
    return mesh;
}

// A cone of cloth round the hips, hanging to the knees (a skirt modelled into the file),
// skinned to `bone` with weight 1, its pattern unwrapped as a tailor's would be: u round
// the body (the seam's vertices twice, at u = 0 and 1), v down it.
aiMesh* modelled_skirt(const char* name, const char* bone, const Vec3& joint, Real top_y, Real bottom_y, Real top_r, Real bottom_r) {
    auto* mesh = new aiMesh();
    mesh->mName = aiString(name);
    mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    constexpr unsigned around = 24, down = 16, columns = around + 1;
    mesh->mNumVertices = columns * down;
    mesh->mVertices = new aiVector3D[columns * down];
    mesh->mNormals = new aiVector3D[columns * down];
    mesh->mTextureCoords[0] = new aiVector3D[columns * down];
    mesh->mNumUVComponents[0] = 2;
    for (unsigned r = 0; r < down; ++r)
        for (unsigned a = 0; a < columns; ++a) {
            const Real u = Real(r) / (down - 1), angle = Real(2 * M_PI * (a % around) / around);
            const Real radius = top_r + u * (bottom_r - top_r), y = top_y + u * (bottom_y - top_y);
            mesh->mVertices[r * columns + a] = aiVector3D(radius * std::cos(angle), y, radius * std::sin(angle));
            mesh->mNormals[r * columns + a] = aiVector3D(std::cos(angle), 0, std::sin(angle));
            mesh->mTextureCoords[0][r * columns + a] = aiVector3D(Real(a) / around, 1 - u, 0);
        }
    mesh->mNumFaces = 2 * around * (down - 1);
    mesh->mFaces = new aiFace[mesh->mNumFaces];
    unsigned f = 0;
    for (unsigned r = 0; r + 1 < down; ++r)
        for (unsigned a = 0; a < around; ++a) {
            const unsigned b = a + 1;
            for (const auto& t : {std::array<unsigned, 3>{r * columns + a, (r + 1) * columns + a, r * columns + b},
                                  std::array<unsigned, 3>{r * columns + b, (r + 1) * columns + a, (r + 1) * columns + b}}) {
                mesh->mFaces[f].mNumIndices = 3;
                mesh->mFaces[f].mIndices = new unsigned[3]{t[0], t[1], t[2]};
                ++f;
            }
        }
    mesh->mNumBones = 1;
    mesh->mBones = new aiBone*[1];
    auto* b = new aiBone();
    b->mName = aiString(bone);
    b->mOffsetMatrix = aiMatrix4x4();
    b->mOffsetMatrix.a4 = -joint.x();
    b->mOffsetMatrix.b4 = -joint.y();
    b->mOffsetMatrix.c4 = -joint.z();
    b->mNumWeights = mesh->mNumVertices;
    b->mWeights = new aiVertexWeight[mesh->mNumVertices];
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) b->mWeights[v] = aiVertexWeight(v, 1.0f);
    mesh->mBones[0] = b;
    return mesh;
}

void add_meshes(aiScene& scene, aiNode* node, std::vector<aiMesh*> meshes) {
    const unsigned old_count = scene.mNumMeshes;
    auto** all = new aiMesh*[old_count + meshes.size()];
    for (unsigned i = 0; i < old_count; ++i) all[i] = scene.mMeshes[i];
    node->mNumMeshes = static_cast<unsigned>(meshes.size());
    node->mMeshes = new unsigned[meshes.size()];
    for (std::size_t i = 0; i < meshes.size(); ++i) {
        all[old_count + i] = meshes[i];
        node->mMeshes[i] = old_count + static_cast<unsigned>(i);
    }
    delete[] scene.mMeshes;
    scene.mMeshes = all;
    scene.mNumMeshes = old_count + static_cast<unsigned>(meshes.size());
}

void write(const aiScene& scene, const fs::path& file) {
    Assimp::Exporter exporter;
    ASSERT_EQ(exporter.Export(&scene, "glb2", file.string()), AI_SUCCESS) << exporter.GetErrorString();
}

// The avatar with its bones named Bone.000, Bone.001, ... (the clips follow).
AvatarModel renamed(AvatarModel m) {
    for (std::size_t i = 0; i < m.bones.size(); ++i) {
        char name[32];
        std::snprintf(name, sizeof name, "Bone.%03zu", i);
        m.bones[i].name = name;
    }
    return m;
}

// The avatar in centimetres (a glTF file stating metres, 175 of them tall).
AvatarModel in_centimetres(AvatarModel m) {
    m.positions *= 100;
    for (AvatarBone& b : m.bones) b.joint_m *= 100;
    for (AvatarClip& clip : m.clips)
        for (auto& frame : clip.translations)
            for (auto& t : frame) t *= 100;
    return m;
}

// The avatar on a base block 8 cm thick (not skinned: a node of its own) with a prop at its
// feet skinned to a bone of its own that hangs from the scene's root.
void write_with_base_and_prop(const fs::path& file) {
    const std::unique_ptr<aiScene> scene = to_assimp_scene(avatar());
    auto* base = new aiNode("Base");
    add_meshes(*scene, base, {box("Base", Vec3(-0.5f, -0.08f, -0.5f), Vec3(0.5f, 0, 0.5f))});
    auto* holder = new aiNode("PropHolder");
    const Vec3 at(0.5f, 0, 0.2f);
    holder->mTransformation.a4 = at.x();
    holder->mTransformation.c4 = at.z();
    auto* prop_node = new aiNode("PropMesh");
    aiMesh* prop = box("Lantern", Vec3(0.45f, 0, 0.15f), Vec3(0.57f, 0.3f, 0.27f));
    prop->mNumBones = 1;
    prop->mBones = new aiBone*[1];
    auto* b = new aiBone();
    b->mName = aiString("PropHolder");
    b->mOffsetMatrix.a4 = -at.x();
    b->mOffsetMatrix.c4 = -at.z();
    b->mNumWeights = 8;
    b->mWeights = new aiVertexWeight[8];
    for (unsigned v = 0; v < 8; ++v) b->mWeights[v] = aiVertexWeight(v, 1.0f);
    prop->mBones[0] = b;
    add_meshes(*scene, prop_node, {prop});
    std::array<aiNode*, 3> extra{base, holder, prop_node};
    scene->mRootNode->addChildren(3, extra.data());
    write(*scene, file);
}

// The avatar with a skirt modelled into the file (named so), skinned to its hips.
void write_with_modelled_skirt(const fs::path& file, const char* name) {
    const AvatarModel& m = avatar();
    const std::unique_ptr<aiScene> scene = to_assimp_scene(m);
    const int hips = m.find_bone("Hips");
    ASSERT_GE(hips, 0);
    const Vec3 joint = m.bones[std::size_t(hips)].joint_m.cast<Real>();
    auto* node = new aiNode("SkirtNode");
    add_meshes(*scene, node, {modelled_skirt(name, "Hips", joint, joint.y() + 0.08f, joint.y() - 0.45f, 0.17f, 0.3f)});
    scene->mRootNode->addChildren(1, &node);
    write(*scene, file);
}

CharacterBody fitted(const fs::path& file, std::shared_ptr<const CharacterAsset>* asset = nullptr) {
    auto c = import_character(file);
    EXPECT_TRUE(c) << (c ? "" : c.error().message);
    if (!c) return {};
    auto body = fit_character_body(**c);
    EXPECT_TRUE(body) << (body ? "" : body.error().message);
    if (asset) *asset = *c;
    return body ? *body : CharacterBody{};
}

// Every landmark within 3 cm of the unmodified avatar's.
void expect_same_landmarks(const BodyLandmarks& a, const BodyLandmarks& b) {
    constexpr Real within = 0.03f;
    EXPECT_NEAR(a.crotch_m, b.crotch_m, within);
    EXPECT_NEAR(a.underarm_m, b.underarm_m, within);
    EXPECT_NEAR(a.floor_m, b.floor_m, within);
    EXPECT_NEAR(a.height_m, b.height_m, within);
    EXPECT_LT((a.waist.center.rest_m - b.waist.center.rest_m).norm(), within);
    EXPECT_LT((a.hips.center.rest_m - b.hips.center.rest_m).norm(), within);
    EXPECT_LT((a.chest.center.rest_m - b.chest.center.rest_m).norm(), within);
    EXPECT_LT((a.arms_meet_trunk.rest_m - b.arms_meet_trunk.rest_m).norm(), within);
    EXPECT_LT((a.left_shoulder.rest_m - b.left_shoulder.rest_m).norm(), within);
    EXPECT_LT((a.right_shoulder.rest_m - b.right_shoulder.rest_m).norm(), within);
    EXPECT_NEAR(a.waist.girth_m, b.waist.girth_m, 2 * within);
    EXPECT_NEAR(a.chest.girth_m, b.chest.girth_m, 2 * within);
    EXPECT_EQ(a.how_found.size(), b.how_found.size());
}

const BodyLandmarks& original() {
    static const CharacterBody body = fitted(test::source_dir() / "assets/avatar.glb");
    EXPECT_TRUE(body.landmarks);
    return *body.landmarks;
}

TEST(CharacterVariants, GenericBoneNamesGiveTheSameLandmarksByTopology) {
    const fs::path file = temp_file("renamed");
    ASSERT_TRUE(write_avatar(renamed(avatar()), file));
    const CharacterBody body = fitted(file);
    ASSERT_TRUE(body.landmarks) << body.landmarks_error;
    EXPECT_EQ(body.landmarks->found_by, "topology");
    expect_same_landmarks(*body.landmarks, original());
    // inspect prints each landmark and how it was found.
    auto asset = import_character(file);
    ASSERT_TRUE(asset);
    const std::string report = character_report_text(**asset, body, rest_pose_coverage(**asset, body));
    for (const char* line : {"pelvis                  'Bone.000': topology", "crotch ", "hips ", "waist ", "chest ",
                             "under the arms ", "shoulders "})
        EXPECT_NE(report.find(std::string("    ") + line), std::string::npos) << line << "\n" << report;
}

TEST(CharacterVariants, ABaseAndAPropAreLeftOutOfTheBody) {
    const fs::path file = temp_file("base_and_prop");
    write_with_base_and_prop(file);
    std::shared_ptr<const CharacterAsset> asset;
    const CharacterBody body = fitted(file, &asset);
    ASSERT_TRUE(asset);
    ASSERT_TRUE(body.landmarks) << body.landmarks_error;
    expect_same_landmarks(*body.landmarks, original());
    ASSERT_EQ(body.left_out.size(), 2u);
    for (const LeftOutMesh& x : body.left_out) {
        EXPECT_FALSE(x.garment) << x.why;
        EXPECT_NE(asset->meshes.at(x.mesh).name, "Body") << x.why;
    }
    // No ellipsoid on the root or the prop's bone, none reaching the base.
    for (const EllipsoidShape& e : body.ellipsoids) {
        const std::string& bone = asset->skeleton->bone_names.at(std::size_t(e.bone));
        EXPECT_NE(bone, "PropHolder");
        EXPECT_NE(bone, asset->skeleton->bone_names.at(0));
    }
    const std::string report = character_report_text(*asset, body, rest_pose_coverage(*asset, body));
    EXPECT_NE(report.find("left out    2 meshes"), std::string::npos) << report;
    EXPECT_NE(report.find("Lantern"), std::string::npos) << report;
}

TEST(CharacterVariants, CentimetreUnitsGiveTheSameLandmarks) {
    const fs::path file = temp_file("centimetres");
    ASSERT_TRUE(write_avatar(in_centimetres(avatar()), file));
    std::shared_ptr<const CharacterAsset> asset;
    const CharacterBody body = fitted(file, &asset);
    ASSERT_TRUE(asset);
    EXPECT_EQ(asset->scale_source, ScaleSource::fallback);
    EXPECT_NE(asset->units_note.find("glTF: metres"), std::string::npos) << asset->units_note;
    EXPECT_NE(asset->units_note.find("scaled to 1.75 m instead"), std::string::npos) << asset->units_note;
    ASSERT_TRUE(body.landmarks) << body.landmarks_error;
    expect_same_landmarks(*body.landmarks, original());
}

// A skirt modelled into the file, found by its name or, named like anything, by the cloth
// between the legs: left out of the fit (the landmarks are the body's), and not drawn while
// a simulated garment is put on over it unless the scene says otherwise.
TEST(CharacterVariants, AModelledSkirtIsLeftOutAndHiddenUnderASimulatedOne) {
    for (const char* name : {"Skirt", "Cloth_01"}) {
        SCOPED_TRACE(name);
        const fs::path file = temp_file(std::string("modelled_") + name);
        write_with_modelled_skirt(file, name);
        std::shared_ptr<const CharacterAsset> asset;
        const CharacterBody body = fitted(file, &asset);
        ASSERT_TRUE(body.landmarks) << body.landmarks_error;
        ASSERT_EQ(body.left_out.size(), 1u);
        EXPECT_TRUE(body.left_out[0].garment) << body.left_out[0].why;
        EXPECT_EQ(asset->meshes.at(body.left_out[0].mesh).name, name);
        expect_same_landmarks(*body.landmarks, original());
        for (const bool hide : {true, false}) {
            SceneDescription scene = sample_scene();
            scene.characters.at(0).file = file;
            scene.characters.at(0).hide_modelled_garments = hide;
            scene.solver.settle_s = 0;
            auto world = build_world(scene, {});
            ASSERT_TRUE(world) << world.error().message;
            const auto& skin = world->registry.get<SkinnedMesh>(world->characters.at(0));
            const bool hidden = body.left_out[0].mesh < skin.hidden.size() && skin.hidden[body.left_out[0].mesh];
            EXPECT_EQ(hidden, hide);
        }
    }
}

// A skirt modelled into the character's file becomes the cloth: the scene's garment names
// the character's own file (and the mesh, or the one modelled garment); the mesh is read as
// the character was (units, axes), placed from its bind pose, and no longer drawn skinned.
TEST(CharacterVariants, AModelledSkirtOfTheCharactersOwnFileBecomesTheCloth) {
    const fs::path file = temp_file("own_skirt");
    write_with_modelled_skirt(file, "Skirt");
    const int hips = avatar().find_bone("Hips");
    ASSERT_GE(hips, 0);
    const Real joint_y = avatar().bones[std::size_t(hips)].joint_m.cast<Real>().y();
    const Real top_y = joint_y + Real(0.08), bottom_y = joint_y - Real(0.45), top_r = Real(0.17), bottom_r = Real(0.3);
    for (const char* mesh : {"", "Skirt"}) {
        SCOPED_TRACE(mesh);
        SceneDescription scene = sample_scene();
        scene.characters.at(0).file = file;
        scene.characters.at(0).hide_modelled_garments = false;  // hidden all the same: it is the cloth now
        GarmentDescription g;
        g.file = file;
        g.mesh = mesh;
        scene.garments = {g};
        scene.solver.settle_s = 0;
        auto world = build_world(scene, {});
        ASSERT_TRUE(world) << world.error().message;
        const Entity character = world->characters.at(0);
        const auto& skin = world->registry.get<SkinnedMesh>(character);
        std::size_t skirt_mesh = skin.mesh->submeshes.size();
        for (std::size_t k = 0; k < skin.mesh->submeshes.size(); ++k)
            if (skin.mesh->submeshes[k].name == "Skirt") skirt_mesh = k;
        ASSERT_LT(skirt_mesh, skin.mesh->submeshes.size());
        EXPECT_TRUE(skirt_mesh < skin.hidden.size() && skin.hidden[skirt_mesh]) << "the modelled skirt is not drawn skinned under its cloth";
        // The cloth where the skirt was modelled (the sample scene's first pose stands as the
        // bind pose's trunk does): its particles on the cone, in the character's model space.
        const Garment& cloth = world->registry.get<Garment>(world->garments.at(0));
        const auto* placed = world->registry.try_get<Transform>(character);
        const Affine3 to_model = placed ? Affine3(placed->matrix().inverse()) : Affine3::Identity();
        std::vector<Real> off;
        for (Eigen::Index p = 0; p < cloth.state.x.cols(); ++p) {
            const Vec3 q = to_model * Vec3(cloth.state.x.col(p));
            const Real along = std::clamp((top_y - q.y()) / (top_y - bottom_y), Real(0), Real(1));
            off.push_back(std::abs(std::hypot(q.x(), q.z()) - (top_r + along * (bottom_r - top_r))));
            EXPECT_GT(q.y(), bottom_y - Real(0.03));
            EXPECT_LT(q.y(), top_y + Real(0.03));
        }
        std::nth_element(off.begin(), off.begin() + static_cast<std::ptrdiff_t>(off.size() / 2), off.end());
        EXPECT_LT(off[off.size() / 2], Real(0.015)) << "median distance of the cloth from the modelled cone";
        for (int frame = 0; frame < 30; ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        EXPECT_TRUE(world->registry.get<Garment>(world->garments.at(0)).state.x.allFinite());
    }
    // A mesh the file does not hold, and a file with no modelled garment: one line naming them.
    SceneDescription scene = sample_scene();
    scene.characters.at(0).file = file;
    GarmentDescription g;
    g.file = file;
    g.mesh = "Belt";
    scene.garments = {g};
    auto belt = build_world(scene, {});
    ASSERT_FALSE(belt);
    EXPECT_NE(belt.error().message.find("garments[0]: " + file.string() + ": no mesh named 'Belt' (meshes: "), std::string::npos)
        << belt.error().message;
    const fs::path plain = temp_file("no_modelled_garment");
    write(*to_assimp_scene(avatar()), plain);
    scene.characters.at(0).file = plain;
    scene.garments.at(0).file = plain;
    scene.garments.at(0).mesh.clear();
    auto none = build_world(scene, {});
    ASSERT_FALSE(none);
    EXPECT_NE(none.error().message.find("holds no modelled garment: name the mesh to simulate as"), std::string::npos)
        << none.error().message;
}

}  // namespace
}  // namespace drape
