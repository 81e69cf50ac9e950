// COLLADA through the same import path: assimp applies the file's <unit> and <up_axis>;
// the result must be metres and Y up like every other character.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "drape/engine/assets/character_import.hpp"
#include "drape/systems/character/pose.hpp"
#include "tests/character/test_character_file.hpp"

namespace drape {
namespace {

// A column 200 cm tall along +Z (Z up, centimetres), skinned to Root and Child (100 cm up);
// one clip turns Child 90 degrees about X over 1 s.
std::string collada_column() {
    std::ostringstream pos, tri, vcount, v;
    const int rings = 5, around = 4;
    for (int r = 0; r < rings; ++r)
        for (int k = 0; k < around; ++k) {
            const double a = 2 * M_PI * k / around;
            pos << 20 * std::cos(a) << ' ' << 20 * std::sin(a) << ' ' << 50 * r << ' ';
            vcount << (r == 2 ? 2 : 1) << ' ';
            if (r < 2) v << "0 0 ";
            else if (r == 2) v << "0 1 1 1 ";
            else v << "1 0 ";
        }
    int triangles = 0;
    for (int r = 0; r + 1 < rings; ++r)
        for (int k = 0; k < around; ++k) {
            const int a = r * around + k, b = r * around + (k + 1) % around;
            tri << a << ' ' << b << ' ' << a + around << ' ' << b << ' ' << b + around << ' ' << a + around << ' ';
            triangles += 2;
        }
    const char* identity = "1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1";
    std::ostringstream d;
    d << R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="centimeter" meter="0.01"/><up_axis>Z_UP</up_axis></asset>
  <library_geometries><geometry id="geom" name="Column"><mesh>
    <source id="pos"><float_array id="pos-array" count=")" << rings * around * 3 << "\">" << pos.str() << R"(</float_array>
      <technique_common><accessor source="#pos-array" count=")" << rings * around << R"(" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
    <vertices id="verts"><input semantic="POSITION" source="#pos"/></vertices>
    <triangles count=")" << triangles << R"("><input semantic="VERTEX" source="#verts" offset="0"/><p>)" << tri.str() << R"(</p></triangles>
  </mesh></geometry></library_geometries>
  <library_controllers><controller id="skin"><skin source="#geom">
    <bind_shape_matrix>)" << identity << R"(</bind_shape_matrix>
    <source id="joints"><Name_array id="joints-array" count="2">Root Child</Name_array>
      <technique_common><accessor source="#joints-array" count="2" stride="1"><param name="JOINT" type="name"/></accessor></technique_common></source>
    <source id="binds"><float_array id="binds-array" count="32">)" << identity << R"( 1 0 0 0 0 1 0 0 0 0 1 -100 0 0 0 1</float_array>
      <technique_common><accessor source="#binds-array" count="2" stride="16"><param name="TRANSFORM" type="float4x4"/></accessor></technique_common></source>
    <source id="weights"><float_array id="weights-array" count="2">1 0.5</float_array>
      <technique_common><accessor source="#weights-array" count="2" stride="1"><param name="WEIGHT" type="float"/></accessor></technique_common></source>
    <joints><input semantic="JOINT" source="#joints"/><input semantic="INV_BIND_MATRIX" source="#binds"/></joints>
    <vertex_weights count=")" << rings * around << R"("><input semantic="JOINT" source="#joints" offset="0"/><input semantic="WEIGHT" source="#weights" offset="1"/>
      <vcount>)" << vcount.str() << "</vcount><v>" << v.str() << R"(</v></vertex_weights>
  </skin></controller></library_controllers>
  <library_animations><animation id="bend" name="Bend">
    <source id="t"><float_array id="t-array" count="2">0 1</float_array>
      <technique_common><accessor source="#t-array" count="2" stride="1"><param name="TIME" type="float"/></accessor></technique_common></source>
    <source id="m"><float_array id="m-array" count="32">1 0 0 0 0 1 0 0 0 0 1 100 0 0 0 1 1 0 0 0 0 0 -1 0 0 1 0 100 0 0 0 1</float_array>
      <technique_common><accessor source="#m-array" count="2" stride="16"><param name="TRANSFORM" type="float4x4"/></accessor></technique_common></source>
    <source id="interp"><Name_array id="interp-array" count="2">LINEAR LINEAR</Name_array>
      <technique_common><accessor source="#interp-array" count="2" stride="1"><param name="INTERPOLATION" type="name"/></accessor></technique_common></source>
    <sampler id="s"><input semantic="INPUT" source="#t"/><input semantic="OUTPUT" source="#m"/><input semantic="INTERPOLATION" source="#interp"/></sampler>
    <channel source="#s" target="Child/transform"/>
  </animation></library_animations>
  <library_visual_scenes><visual_scene id="scene">
    <node id="Root" name="Root" sid="Root" type="JOINT"><matrix sid="transform">)" << identity << R"(</matrix>
      <node id="Child" name="Child" sid="Child" type="JOINT"><matrix sid="transform">1 0 0 0 0 1 0 0 0 0 1 100 0 0 0 1</matrix></node>
    </node>
    <node id="Body" name="Body"><instance_controller url="#skin"><skeleton>#Root</skeleton></instance_controller></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
)";
    return d.str();
}

TEST(ColladaImport, CentimetresAndZUpBecomeMetresAndYUp) {
    const auto dir = test::temp_dir("collada");
    std::ofstream(dir / "column.dae") << collada_column();
    auto r = import_character(dir / "column.dae");
    std::filesystem::remove_all(dir);
    ASSERT_TRUE(r) << r.error().message;
    const CharacterAsset& c = **r;
    EXPECT_NEAR(c.height_m, 2.0f, 1e-3f);
    EXPECT_EQ(c.scale_source, ScaleSource::file_units);
    ASSERT_EQ(c.clips.size(), 1u);
    EXPECT_NEAR(c.clips[0]->duration_s, 1.0, 1e-6);
    ASSERT_GE(c.skeleton->find("Child"), 0);
    // Rest pose: the column stands along +Y from y = 0 to 2 m.
    std::vector<Affine3> global, skinning;
    compose_pose(*c.skeleton, c.skeleton->rest_local, global);
    skinning_matrices(*c.skeleton, global, skinning);
    Matrix3X p;
    skin_positions(*c.mesh, skinning, Affine3::Identity(), p);
    EXPECT_NEAR(p.row(1).minCoeff(), 0.0f, 1e-4f);
    EXPECT_NEAR(p.row(1).maxCoeff(), 2.0f, 1e-4f);
    EXPECT_LE(p.row(0).cwiseAbs().maxCoeff(), 0.2f + 1e-4f);
    // The Child joint sits 1 m up.
    EXPECT_TRUE(global[std::size_t(c.skeleton->find("Child"))].translation().isApprox(Vec3(0, 1, 0), 1e-4f))
        << global[std::size_t(c.skeleton->find("Child"))].translation().transpose();
}

}  // namespace
}  // namespace drape
