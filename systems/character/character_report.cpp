// Character reports: see character_report.hpp.
#include "drape/systems/character/character_report.hpp"

#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "drape/engine/assets/character_import.hpp"
#include "drape/systems/character/pose.hpp"

namespace drape {
namespace {

std::string format(const char* fmt, auto... args) {
    char buffer[512];
    std::snprintf(buffer, sizeof buffer, fmt, args...);
    return buffer;
}

std::size_t triangles(const Submesh& s) { return s.index_count / 3; }

}  // namespace

CoverageReport rest_pose_coverage(const CharacterAsset& c, const CharacterBody& body, double tolerance_m) {
    std::vector<Affine3> global, skinning;
    compose_pose(*c.skeleton, c.skeleton->rest_local, global);
    skinning_matrices(*c.skeleton, global, skinning);
    Matrix3X positions, normals;
    skin_mesh(*c.mesh, skinning, Affine3::Identity(), positions, normals);
    return measure_coverage(body.ellipsoids, global, positions, normals, c.mesh->indices, tolerance_m);
}

std::string character_report_text(const CharacterAsset& c, const CharacterBody& body, const CoverageReport& r) {
    const SkeletonAsset& s = *c.skeleton;
    const MeshAsset& m = *c.mesh;
    std::string out = c.source.string() + "\n";
    out += format("  height      %.3f m (scale %.6g from %s)\n", double(c.height_m), c.scale, scale_source_name(c.scale_source));
    if (!c.units_note.empty()) out += "  units       " + c.units_note + "\n";
    out += format("  meshes      %zu, %zu vertices, %zu triangles\n", c.meshes.size(), m.vertex_count(), m.indices.size() / 3);
    for (std::size_t i = 0; i < c.meshes.size(); ++i)
        out += format("    %-28s %6u vertices %6zu triangles%s\n", c.meshes[i].name.c_str(), c.meshes[i].vertex_count,
                      i < m.submeshes.size() ? triangles(m.submeshes[i]) : std::size_t(0),
                      c.meshes[i].rigid ? "  (rigid, bound to its bone)" : "");
    out += format("  bones       %zu in the skeleton, %d move vertices; hips: %s\n", s.size(), c.skin_bones,
                  body.hip_bone >= 0 ? s.bone_names[std::size_t(body.hip_bone)].c_str() : "none found");
    if (const auto& l = body.landmarks) {
        auto bone = [&](int b) { return b >= 0 ? s.bone_names[std::size_t(b)].c_str() : "-"; };
        out += format("  body        %.3f m tall (floor %.3f, top %.3f); pelvis %s (by %s), chest %s, head %s\n", double(l->height_m),
                      double(l->floor_m), double(l->top_m), bone(l->pelvis_bone), l->found_by.c_str(), bone(l->chest_bone),
                      bone(l->head_bone));
        out += format("  landmarks   crotch %.3f m, waist %.3f m (girth %.3f m), hips %.3f m (girth %.3f m), chest %.3f m (girth %.3f m), "
                      "under the arms %.3f m\n",
                      double(l->crotch_m), double(l->waist.center.rest_m.y()), double(l->waist.girth_m), double(l->hips.center.rest_m.y()),
                      double(l->hips.girth_m), double(l->chest.center.rest_m.y()), double(l->chest.girth_m), double(l->underarm_m));
        out += format("  limbs       legs %s, %s; arms %s, %s (left, right)\n", bone(l->left_leg.root), bone(l->right_leg.root),
                      bone(l->left_arm.root), bone(l->right_arm.root));
        auto height_of = [&](const std::string& name) -> double {
            if (name == "crotch") return l->crotch_m;
            if (name == "hips") return l->hips.center.rest_m.y();
            if (name == "waist") return l->waist.center.rest_m.y();
            if (name == "chest") return l->chest.center.rest_m.y();
            if (name == "under the arms") return l->underarm_m;
            if (name == "shoulders") return 0.5 * double(l->left_shoulder.rest_m.y() + l->right_shoulder.rest_m.y());
            return 0.0;
        };
        for (const auto& [name, how] : l->how_found) {
            if (name == "pelvis") out += format("    %-15s         %s\n", name.c_str(), how.c_str());
            else out += format("    %-15s %6.3f m %s\n", name.c_str(), height_of(name), how.c_str());
        }
    } else {
        out += "  body        no landmarks: " + body.landmarks_error + "\n";
    }
    if (!body.left_out.empty()) {
        out += format("  left out    %zu meshes of %zu from the body's fit and landmarks\n", body.left_out.size(), c.meshes.size());
        for (const LeftOutMesh& x : body.left_out)
            out += format("    %-28s %s\n", x.mesh < c.meshes.size() ? c.meshes[x.mesh].name.c_str() : "?", x.why.c_str());
    }
    out += format("  clips       %zu\n", c.clips.size());
    for (std::size_t i = 0; i < c.clips.size(); ++i) {
        const AnimationClip& clip = *c.clips[i];
        out += format("    [%zu] %-32s %7.3f s  %3zu channels", i, clip.name.c_str(), clip.duration_s, clip.channels.size());
        if (clip.travel_m.norm() > 1e-3f) out += format("  travels %.2f m", double(clip.travel_m.norm()));
        out += clip_loops(clip) ? "  loops\n" : "  plays once\n";
    }
    out += format("  ellipsoids  %zu fitted, legs %s\n", body.ellipsoids.size(), leg_fit_name(body.legs));
    for (std::size_t i = 0; i < body.ellipsoids.size(); ++i) {
        const EllipsoidShape& e = body.ellipsoids[i];
        out += format("    %-20s %-10s radii %.3f %.3f %.3f m  bulge %.3f m%s\n", s.bone_names[std::size_t(e.bone)].c_str(),
                      body_region_name(e.region), double(e.radii_m.x()), double(e.radii_m.y()), double(e.radii_m.z()),
                      i < r.bulge_per_ellipsoid_m.size() ? r.bulge_per_ellipsoid_m[i] : 0.0,
                      e.give_m > 0 ? format("  give %.3f m", double(e.give_m)).c_str() : "");
    }
    out += format("  coverage    %.1f %% of %zu vertices inside or within %.0f mm (largest gap %.3f m)\n", 100 * r.coverage,
                  r.vertices, 1000 * r.tolerance_m, r.max_gap_m);
    out += format("  bulge       mean %.3f m, p95 %.3f m, max %.3f m out of the body\n", r.mean_bulge_m, r.p95_bulge_m, r.max_bulge_m);
    return out;
}

std::string character_report_json(const CharacterAsset& c, const CharacterBody& body, const CoverageReport& r) {
    using nlohmann::json;
    const SkeletonAsset& s = *c.skeleton;
    const MeshAsset& m = *c.mesh;
    json j;
    j["file"] = c.source.string();
    j["height_m"] = c.height_m;
    j["scale"] = c.scale;
    j["scale_source"] = scale_source_name(c.scale_source);
    j["units"] = c.units_note;
    j["vertices"] = m.vertex_count();
    j["triangles"] = m.indices.size() / 3;
    j["meshes"] = json::array();
    for (std::size_t i = 0; i < c.meshes.size(); ++i)
        j["meshes"].push_back({{"name", c.meshes[i].name}, {"vertices", c.meshes[i].vertex_count},
                               {"triangles", i < m.submeshes.size() ? triangles(m.submeshes[i]) : 0}, {"rigid", c.meshes[i].rigid}});
    j["bones"] = s.size();
    j["skin_bones"] = c.skin_bones;
    j["hip_bone"] = body.hip_bone >= 0 ? json(s.bone_names[std::size_t(body.hip_bone)]) : json(nullptr);
    if (const auto& l = body.landmarks) {
        auto bone = [&](int b) { return b >= 0 ? json(s.bone_names[std::size_t(b)]) : json(nullptr); };
        auto section = [](const BodySection& x) {
            return json{{"height_m", x.center.rest_m.y()}, {"girth_m", x.girth_m}, {"half_width_m", x.half_width_m},
                        {"half_depth_m", x.half_depth_m}};
        };
        j["landmarks"] = {{"height_m", l->height_m}, {"floor_m", l->floor_m}, {"top_m", l->top_m},
                          {"pelvis", bone(l->pelvis_bone)}, {"found_by", l->found_by}, {"chest_bone", bone(l->chest_bone)},
                          {"head", bone(l->head_bone)}, {"crotch_m", l->crotch_m}, {"underarm_m", l->underarm_m},
                          {"waist", section(l->waist)}, {"hips", section(l->hips)}, {"chest", section(l->chest)},
                          {"legs", {bone(l->left_leg.root), bone(l->right_leg.root)}},
                          {"arms", {bone(l->left_arm.root), bone(l->right_arm.root)}}};
        j["landmarks"]["how_found"] = json::object();
        for (const auto& [name, how] : l->how_found) j["landmarks"]["how_found"][name] = how;
    } else {
        j["landmarks"] = nullptr;
        j["landmarks_error"] = body.landmarks_error;
    }
    j["left_out"] = json::array();
    for (const LeftOutMesh& x : body.left_out)
        j["left_out"].push_back({{"mesh", x.mesh < c.meshes.size() ? c.meshes[x.mesh].name : std::string()},
                                 {"garment", x.garment}, {"why", x.why}});
    j["clips"] = json::array();
    for (const auto& clip : c.clips)
        j["clips"].push_back({{"name", clip->name}, {"duration_s", clip->duration_s}, {"channels", clip->channels.size()},
                              {"loops", clip_loops(*clip)}, {"travel_m", {clip->travel_m.x(), clip->travel_m.y(), clip->travel_m.z()}}});
    j["legs"] = leg_fit_name(body.legs);
    j["ellipsoids"] = json::array();
    for (std::size_t i = 0; i < body.ellipsoids.size(); ++i) {
        const EllipsoidShape& e = body.ellipsoids[i];
        j["ellipsoids"].push_back({{"bone", s.bone_names[std::size_t(e.bone)]},
                                   {"region", body_region_name(e.region)},
                                   {"center", {e.center.x(), e.center.y(), e.center.z()}},
                                   {"rotation", {e.rotation.x(), e.rotation.y(), e.rotation.z(), e.rotation.w()}},
                                   {"radii_m", {e.radii_m.x(), e.radii_m.y(), e.radii_m.z()}},
                                   {"bulge_m", i < r.bulge_per_ellipsoid_m.size() ? r.bulge_per_ellipsoid_m[i] : 0.0},
                                   {"give_m", e.give_m}});
    }
    j["coverage"] = {{"share", r.coverage}, {"vertices", r.vertices}, {"covered", r.covered}, {"tolerance_m", r.tolerance_m},
                     {"max_gap_m", r.max_gap_m}, {"mean_bulge_m", r.mean_bulge_m}, {"p95_bulge_m", r.p95_bulge_m},
                     {"max_bulge_m", r.max_bulge_m}};
    return j.dump(2) + "\n";
}

}  // namespace drape
