// Bone-bound ellipsoids follow their bones; velocities and accelerations by finite
// differences over the fixed step (method §2, §3.3); fitting and coverage.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>

#include "drape/components/animation_player.hpp"
#include "drape/components/character.hpp"
#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/components/transform.hpp"
#include "drape/engine/assets/character_import.hpp"
#include "drape/engine/core/scheduler.hpp"
#include "drape/systems/character/body_cache.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character/colliders.hpp"
#include "drape/systems/character/pose.hpp"
#include "drape/systems/character/spawn.hpp"
#include "drape/systems/character_systems.hpp"
#include "drape/systems/collider_system.hpp"
#include "tests/character/test_character_file.hpp"
#include "tests/test_paths.hpp"

namespace drape {
namespace {

// The test column, kept in the build tree under a name of its bytes (written whole, the
// same bytes on every run), so that its body comes from the body cache after its first fit.
std::shared_ptr<const CharacterAsset> column(const test::TestCharacter& spec = {}) {
    namespace fs = std::filesystem;
    const auto dir = test::temp_dir("collider");
    write_test_character(spec, dir / "column.gltf");
    std::ifstream in(dir / "column.gltf", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    fs::remove_all(dir);
    const fs::path kept = test::binary_dir() / "test-characters" / ("column-" + std::to_string(std::hash<std::string>{}(bytes)));
    fs::create_directories(kept);
    if (!fs::exists(kept / "column.gltf")) {
        const fs::path temporary = kept / ("column.gltf." + std::to_string(::getpid()));
        std::ofstream(temporary, std::ios::binary) << bytes;
        fs::rename(temporary, kept / "column.gltf");
    }
    auto r = import_character(kept / "column.gltf");
    EXPECT_TRUE(r) << (r ? "" : r.error().message);
    return r ? *r : nullptr;
}

// The fitted body of a character imported from its file (default fit options), through
// the tests' body cache.
CharacterBody body_of(const CharacterAsset& c) {
    auto body = fit_character_body(c, c.source, FitOptions{}, body_cache_from_environment());
    EXPECT_TRUE(body) << (body ? "" : body.error().message);
    return body ? std::move(*body) : CharacterBody{};
}

Skeleton one_bone(const Affine3& global) {
    Skeleton s;
    s.global = {global};
    return s;
}

TEST(EllipsoidColliders, FollowTheirBone) {
    EllipsoidCollider c;
    c.bone = 0;
    c.center = Vec3(0, 0.5f, 0);
    c.radii_m = Vec3(0.1f, 0.3f, 0.2f);
    Affine3 bone = Affine3::Identity();
    bone.translate(Vec3(1, 2, 3));
    bone.rotate(Eigen::AngleAxis<Real>(Real(M_PI / 2), Vec3::UnitZ()));
    update_collider(c, one_bone(bone), nullptr, 1.0 / 60);
    // The centre is 0.5 m along the bone's Y, which the rotation turns to -X.
    EXPECT_TRUE(c.world.translation().isApprox(Vec3(0.5f, 2, 3), 1e-6f)) << c.world.translation().transpose();
    // A point on the ellipsoid's long axis ends up 0.3 m further along -X.
    EXPECT_TRUE((c.world * Vec3(0, 1, 0)).isApprox(Vec3(0.2f, 2, 3), 1e-5f));
}

TEST(EllipsoidColliders, BoneScaleDoesNotScaleRadiiInMetres) {
    EllipsoidCollider c;
    c.bone = 0;
    c.radii_m = Vec3(0.1f, 0.1f, 0.1f);
    Affine3 bone = Affine3::Identity();
    bone.scale(100.0f);  // an armature in centimetres
    update_collider(c, one_bone(bone), nullptr, 1.0 / 60);
    EXPECT_NEAR((c.world * Vec3(1, 0, 0)).norm(), 0.1f, 1e-6f);
}

TEST(EllipsoidColliders, VelocityAndAccelerationAreFiniteDifferencesOverTheStep) {
    EllipsoidCollider c;
    c.bone = 0;
    const double dt = 0.01;
    auto at = [](double t) {  // x = t^2: v = 2t, a = 2
        Affine3 a = Affine3::Identity();
        a.translate(Vec3(Real(t * t), 0, 0));
        return a;
    };
    update_collider(c, one_bone(at(0)), nullptr, dt);
    EXPECT_TRUE(c.initialised);
    EXPECT_TRUE(c.velocity_m_s.isZero());
    EXPECT_TRUE(c.acceleration_m_s2.isZero());
    update_collider(c, one_bone(at(dt)), nullptr, dt);
    EXPECT_NEAR(c.velocity_m_s.x(), 0.01f, 1e-5f);  // (dt^2 - 0) / dt
    EXPECT_TRUE(c.acceleration_m_s2.isZero());      // no previous velocity yet
    update_collider(c, one_bone(at(2 * dt)), nullptr, dt);
    EXPECT_NEAR(c.velocity_m_s.x(), 0.03f, 1e-4f);
    EXPECT_NEAR(c.acceleration_m_s2.x(), 2.0f, 1e-2f);
    EXPECT_TRUE(c.previous_world.translation().isApprox(at(dt).translation()));
}

TEST(EllipsoidColliders, AngularVelocityOfASpinningBone) {
    EllipsoidCollider c;
    c.bone = 0;
    const double dt = 1.0 / 60, omega = 3.0;
    for (int i = 0; i < 3; ++i) {
        Affine3 bone = Affine3::Identity();
        bone.rotate(Eigen::AngleAxis<Real>(Real(omega * dt * i), Vec3::UnitY()));
        update_collider(c, one_bone(bone), nullptr, dt);
    }
    EXPECT_TRUE(c.angular_velocity_rad_s.isApprox(Vec3(0, Real(omega), 0), 1e-3f)) << c.angular_velocity_rad_s.transpose();
}

TEST(EllipsoidFitting, CoversTheTestColumnAndTagsNothingAsPelvis) {
    const auto c = column();
    ASSERT_TRUE(c);
    const CharacterBody body = body_of(*c);
    ASSERT_FALSE(body.ellipsoids.empty());
    std::vector<Affine3> global, skinning;
    compose_pose(*c->skeleton, c->skeleton->rest_local, global);
    skinning_matrices(*c->skeleton, global, skinning);
    Matrix3X p, n;
    skin_mesh(*c->mesh, skinning, Affine3::Identity(), p, n);
    const CoverageReport r = measure_coverage(body.ellipsoids, global, p, n, c->mesh->indices);
    EXPECT_GE(r.coverage, 0.95);
    EXPECT_EQ(find_hip_bone(*c->skeleton), -1);  // "Root" and "Child" are no hips
    EXPECT_EQ(body.hip_bone, -1);
    for (const EllipsoidShape& s : body.ellipsoids) {
        EXPECT_TRUE(s.radii_m.allFinite());
        EXPECT_GT(s.radii_m.minCoeff(), 0);
    }
}

TEST(EllipsoidFitting, BadOptionsNameTheFileAndTheField) {
    const auto c = column();
    ASSERT_TRUE(c);
    FitOptions bad;
    bad.tolerance_m = 0;
    const auto body = fit_character_body(*c, bad);
    ASSERT_FALSE(body);
    EXPECT_EQ(body.error().message, c->source.string() + ": fit.tolerance_m: must be in (0, 1] m");
}

TEST(EllipsoidFitting, HipBoneIsFoundByNameOrByTheLegs) {
    SkeletonAsset s;
    s.bone_names = {"Armature", "mixamorig:Hips", "LeftUpLeg", "RightUpLeg"};
    s.parents = {-1, 0, 1, 1};
    EXPECT_EQ(find_hip_bone(s), 1);
    s.bone_names = {"Armature", "root_joint", "thigh.L", "thigh.R"};
    EXPECT_EQ(find_hip_bone(s), 1);
    EXPECT_EQ(region_from_bone_name("LeftForeArm"), BodyRegion::lower_arm);
    EXPECT_EQ(region_from_bone_name("LeftLeg"), BodyRegion::lower_leg);
    EXPECT_EQ(region_from_bone_name("UpperLeg.R"), BodyRegion::upper_leg);
}

// A shell 2 cm thin lies 3 cm out from a thick torso piece (a sphere of 10 cm about the
// bone), its skin facing out (+x): thickened inward, its outer face's middle stays at
// 14 cm and its inner face goes the tolerance (1 cm) into the sphere; the same shell with
// its skin facing the other way is thickened the other way, and one with no thick piece
// within reach behind it, or a thicker piece, a rod (its middle radius under twice its thin
// one), or a piece off the trunk, is left as it was.
TEST(EllipsoidFitting, ThinTrunkPiecesAreThickenedInwardToTheThickOnes) {
    const std::vector<Affine3> global = {Affine3(Eigen::Translation<Real, 3>(Vec3(0, 1, 0)))};
    EllipsoidShape sphere;
    sphere.bone = 0;
    sphere.radii_m = Vec3::Constant(0.10f);
    sphere.region = BodyRegion::torso;
    EllipsoidShape shell = sphere;
    shell.center = Vec3(0.13f, 0, 0);
    shell.radii_m = Vec3(0.01f, 0.05f, 0.10f);
    // Skin on the shell's outer face, facing `out`.
    const auto skin = [&](const Vec3& out, Matrix3X& positions, Matrix3X& normals) {
        positions.resize(3, 9);
        normals.resize(3, 9);
        for (int i = 0; i < 9; ++i) {
            positions.col(i) = Vec3(0, 1, 0) + shell.center + Real(0.01) * out + Vec3(0, Real(0.01) * (i % 3 - 1), Real(0.02) * (i / 3 - 1));
            normals.col(i) = out;
        }
    };
    FitOptions options;
    options.thicken_thin_trunk_m = 0.015;
    Matrix3X p, n;
    skin(Vec3::UnitX(), p, n);
    std::vector<EllipsoidShape> shapes = {sphere, shell};
    thicken_thin_trunk_pieces(shapes, global, p, n, options);
    const EllipsoidShape& thick = shapes[1];
    EXPECT_NEAR(thick.center.x() + thick.radii_m.x(), 0.14f, 1e-5f);   // the outer face's middle
    EXPECT_NEAR(thick.center.x() - thick.radii_m.x(), 0.09f, 0.0025f);  // 1 cm into the sphere (2 mm steps)
    EXPECT_EQ(thick.radii_m.y(), 0.05f);
    EXPECT_EQ(thick.radii_m.z(), 0.10f);
    EXPECT_EQ(shapes[0].radii_m, sphere.radii_m);

    // Facing the other way (the sphere is then in front of the skin, not behind it).
    skin(-Vec3::UnitX(), p, n);
    shapes = {sphere, shell};
    thicken_thin_trunk_pieces(shapes, global, p, n, options);
    EXPECT_NEAR(shapes[1].center.x() - shapes[1].radii_m.x(), 0.12f, 1e-5f);  // its inner (-x) face stays
    EXPECT_EQ(shapes[1].radii_m.x(), 0.01f) << "nothing thick within reach behind it (+x)";

    // Far from the thick piece, thicker than the option, a rod, off the trunk, or the option off.
    for (const auto& change : std::vector<std::function<void(EllipsoidShape&, FitOptions&)>>{
             [](EllipsoidShape& e, FitOptions&) { e.center.x() += 0.2f; },
             [](EllipsoidShape& e, FitOptions&) { e.radii_m.x() = 0.02f; },
             [](EllipsoidShape& e, FitOptions&) { e.radii_m.y() = 0.015f; },
             [](EllipsoidShape& e, FitOptions&) { e.region = BodyRegion::upper_arm; },
             [](EllipsoidShape&, FitOptions& o) { o.thicken_thin_trunk_m = 0; }}) {
        EllipsoidShape e = shell;
        FitOptions o = options;
        change(e, o);
        skin(Vec3::UnitX(), p, n);  // the skin on the shell's outer face, moved with a moved shell
        if (e.center.x() > 0.2f) p.row(0).array() += 0.2f;
        shapes = {sphere, e};
        thicken_thin_trunk_pieces(shapes, global, p, n, o);
        EXPECT_EQ(shapes[1].radii_m, e.radii_m);
        EXPECT_EQ(shapes[1].center, e.center);
    }
}

TEST(EllipsoidFitting, OverridesFromJsonReplaceTheFittedShapeOfTheirBone) {
    const auto c = column();
    ASSERT_TRUE(c);
    auto o = ellipsoids_from_json(R"([{"bone": "Child", "center": [0, 0.5, 0], "radii_m": [0.3, 0.6, 0.3], "region": "torso"}])",
                                  *c->skeleton, "scene.json");
    ASSERT_TRUE(o) << o.error().message;
    ASSERT_EQ(o->size(), 1u);
    EXPECT_EQ((*o)[0].region, BodyRegion::torso);
    const auto merged = apply_overrides(body_of(*c).ellipsoids, *o);
    const int child = c->skeleton->find("Child");
    EXPECT_EQ(std::count_if(merged.begin(), merged.end(), [&](auto& s) { return s.bone == child; }), 1);
    EXPECT_TRUE(std::any_of(merged.begin(), merged.end(), [&](auto& s) { return s.radii_m.y() == 0.6f; }));

    auto bad = ellipsoids_from_json(R"([{"bone": "Tail", "center": [0,0,0], "radii_m": [1,1,1]}])", *c->skeleton, "scene.json");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().message, "scene.json: colliders[0].bone: no bone named 'Tail'");
    bad = ellipsoids_from_json(R"([{"bone": "Child", "center": [0,0,0], "radii_m": [1,0,1]}])", *c->skeleton, "scene.json");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().message, "scene.json: colliders[0].radii_m: must be > 0");
    // The give has the scene files' range: a flat hand's fitted give may pass its thickness.
    auto give = ellipsoids_from_json(R"([{"bone": "Child", "center": [0,0,0], "radii_m": [0.02,0.1,0.1], "give_m": 0.03}])", *c->skeleton, "scene.json");
    ASSERT_TRUE(give) << give.error().message;
    EXPECT_FLOAT_EQ((*give)[0].give_m, 0.03f);
    bad = ellipsoids_from_json(R"([{"bone": "Child", "center": [0,0,0], "radii_m": [1,1,1], "give_m": 0.6}])", *c->skeleton, "scene.json");
    ASSERT_FALSE(bad);
    EXPECT_EQ(bad.error().message, "scene.json: colliders[0].give_m: must be a number in [0, 0.5] m");
}

TEST(CharacterSystems, SpawnedCharacterAnimatesSkinsAndMovesItsColliders) {
    const auto c = column();
    ASSERT_TRUE(c);
    Registry registry;
    SpawnOptions options;
    options.transform.position = Vec3(3, 0, 0);
    const CharacterBody body = body_of(*c);
    auto e = spawn_character(registry, c, body, options);
    ASSERT_TRUE(e) << e.error().message;
    const auto colliders = colliders_of(registry, *e);
    ASSERT_EQ(colliders.size(), body.ellipsoids.size());
    // Valid at once: the skinned mesh is the rest mesh moved to x = 3.
    const SkinnedMesh& skin = registry.get<SkinnedMesh>(*e);
    EXPECT_NEAR(skin.positions.row(0).mean(), 3.0f, 1e-4f);

    Scheduler scheduler;
    add_character_systems(scheduler);
    EXPECT_EQ(scheduler.system_names(Phase::animation), (std::vector<std::string>{"animation"}));
    EXPECT_EQ(scheduler.system_names(Phase::skinning), (std::vector<std::string>{"colliders"}));
    EXPECT_TRUE(scheduler.system_names(Phase::render).empty());  // the mesh is skinned only where it is drawn
    const int child = c->skeleton->find("Child");
    const auto top = std::find_if(colliders.begin(), colliders.end(),
                                  [&](Entity x) { return registry.get<EllipsoidCollider>(x).bone == child; });
    ASSERT_NE(top, colliders.end());
    const Vec3 before = registry.get<EllipsoidCollider>(*top).world.translation();
    for (int i = 0; i < 30; ++i) ASSERT_TRUE(scheduler.tick(registry, 1.0 / 60));  // half the bend
    const EllipsoidCollider& moved = registry.get<EllipsoidCollider>(*top);
    EXPECT_TRUE(moved.initialised);
    EXPECT_GT((moved.world.translation() - before).norm(), 0.05f);
    EXPECT_GT(moved.velocity_m_s.norm(), 0.0f);
    // The collider sits where its bone's pose says (in place: root travel removed).
    const Skeleton& skeleton = registry.get<Skeleton>(*e);
    const EllipsoidShape& shape = *std::find_if(body.ellipsoids.begin(), body.ellipsoids.end(), [&](auto& s) { return s.bone == child; });
    const Affine3 expected = registry.get<Transform>(*e).matrix() * ellipsoid_transform(shape, skeleton.global[std::size_t(child)]);
    EXPECT_TRUE(moved.world.isApprox(expected, 1e-5f));
    EXPECT_NEAR(skeleton.global[0].translation().z(), 0.0f, 1e-5f);

    despawn_character(registry, *e);
    EXPECT_EQ(registry.alive(), 0u);
}

TEST(CharacterSystems, SpawnRejectsAClipThatIsNotThere) {
    const auto c = column();
    ASSERT_TRUE(c);
    Registry registry;
    SpawnOptions options;
    options.clip = "Run";
    auto e = spawn_character(registry, c, body_of(*c), options);
    ASSERT_FALSE(e);
    EXPECT_NE(e.error().message.find("no clip named 'Run'"), std::string::npos);
    EXPECT_EQ(registry.alive(), 0u);
}

TEST(CharacterSystems, SpawnRejectsABodyWhoseBonesAreNotInTheSkeleton) {
    const auto c = column();
    ASSERT_TRUE(c);
    Registry registry;
    CharacterBody body = body_of(*c);
    ASSERT_FALSE(body.ellipsoids.empty());
    body.ellipsoids.back().bone = 99;  // as if fitted to a character with more bones
    auto e = spawn_character(registry, c, body);
    ASSERT_FALSE(e);
    EXPECT_NE(e.error().message.find("body.ellipsoids[" + std::to_string(body.ellipsoids.size() - 1) + "].bone: out of range"),
              std::string::npos)
        << e.error().message;
    EXPECT_EQ(registry.alive(), 0u);
}

TEST(CharacterSystems, ColliderOverridesReplaceOrAddAndAreValidated) {
    const auto c = column();
    ASSERT_TRUE(c);
    Registry registry;
    SpawnOptions options;
    EllipsoidShape big;
    big.bone = c->skeleton->find("Child");
    big.radii_m = Vec3(0.5f, 0.5f, 0.5f);
    options.collider_overrides = {big};
    options.replace_fitted_colliders = true;
    auto e = spawn_character(registry, c, body_of(*c), options);
    ASSERT_TRUE(e) << e.error().message;
    const auto only = colliders_of(registry, *e);
    ASSERT_EQ(only.size(), 1u);
    EXPECT_EQ(registry.get<EllipsoidCollider>(only[0]).radii_m, big.radii_m);
    EXPECT_FALSE(registry.get<EllipsoidCollider>(only[0]).initialised);  // velocities start with the first step

    options.collider_overrides[0].radii_m.y() = 0;
    auto bad = spawn_character(registry, c, body_of(*c), options);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("colliders[0].radii_m: must be > 0"), std::string::npos) << bad.error().message;
    options.collider_overrides[0].radii_m.y() = 0.5f;
    options.collider_overrides[0].bone = 99;
    bad = spawn_character(registry, c, body_of(*c), options);
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("colliders[0].bone: out of range"), std::string::npos);
}

TEST(CharacterSystems, CollidersOfAMovingCharacterCarryItsVelocity) {
    const auto c = column();
    ASSERT_TRUE(c);
    Registry registry;
    SpawnOptions options;
    options.speed = 0;  // hold the pose; only the Transform moves
    auto e = spawn_character(registry, c, body_of(*c), options);
    ASSERT_TRUE(e);
    Scheduler scheduler;
    add_character_systems(scheduler);
    const double dt = scheduler.settings().fixed_dt_s;
    for (int i = 0; i < 5; ++i) {
        registry.get<Transform>(*e).position.x() += Real(2.0 * dt);  // 2 m/s along X
        ASSERT_TRUE(scheduler.tick(registry, dt));
    }
    for (Entity x : colliders_of(registry, *e)) {
        const EllipsoidCollider& col = registry.get<EllipsoidCollider>(x);
        EXPECT_TRUE(col.velocity_m_s.isApprox(Vec3(2, 0, 0), 1e-3f)) << col.velocity_m_s.transpose();
        EXPECT_LE(col.acceleration_m_s2.norm(), 1e-2f);
        EXPECT_LE(col.angular_velocity_rad_s.norm(), 1e-4f);
    }
}

}  // namespace
}  // namespace drape
