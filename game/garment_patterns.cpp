#include "drape/game/garment_patterns.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <optional>

#include "drape/components/body_landmarks.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/game/world.hpp"
#include "drape/systems/character/body_landmarks.hpp"

namespace drape {
namespace {

constexpr Real pi = std::numbers::pi_v<Real>;
constexpr Real mesh_step_m = Real(0.015);  // the pattern's own mesh, finer than the cloth's grid
constexpr Real uv_per_m = Real(0.5);       // UV units per metre of fabric
constexpr Real panel_gap_m = Real(0.04);   // between pieces in the UV layout
constexpr Real held_band_m = Real(0.012);  // painted held from the top edge down this far

// Where a garment's top edge runs round the body: the point at angle theta (0 at the
// body's front, +Z; pi / 2 at its left, +X) and the horizontal direction away from the axis.
struct Edge {
    std::function<Vec3(Real)> at;
    Vec3 axis;  // a point on the body's vertical axis
};

// The closed band a built-in garment is held by (its row 0), as an edge by angle.
Edge band_of(const Garment& g) {
    const Fabric& f = *g.fabric;
    std::vector<std::pair<Real, Vec3>> ring;
    Vec3 axis = Vec3::Zero();
    for (std::uint32_t line = 0; line < f.warp_lines; ++line) axis += g.state.x.col(f.grid[line * f.particles_per_line]);
    axis /= Real(f.warp_lines);
    for (std::uint32_t line = 0; line < f.warp_lines; ++line) {
        const Vec3 p = g.state.x.col(f.grid[line * f.particles_per_line]);
        Real theta = std::atan2(p.x() - axis.x(), p.z() - axis.z());
        if (theta < 0) theta += 2 * pi;
        ring.emplace_back(theta, p);
    }
    std::sort(ring.begin(), ring.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    return Edge{[ring](Real theta) {
                    theta = std::fmod(std::fmod(theta, 2 * pi) + 2 * pi, 2 * pi);
                    std::size_t k = 0;
                    while (k < ring.size() && ring[k].first <= theta) ++k;
                    const auto& [ta, a] = ring[(k + ring.size() - 1) % ring.size()];
                    const auto& [tb, b] = ring[k % ring.size()];
                    Real span = tb - ta, into = theta - ta;
                    if (span <= 0) span += 2 * pi;
                    if (into < 0) into += 2 * pi;
                    return Vec3(a + (b - a) * (into / span));
                },
                axis};
}

// A piece hanging from `edge` between angles from and to: flared by `flare_rad` from the
// vertical, `length_m` long. Appends its vertices (UVs laid out from u_offset) and triangles.
// Returns the piece's widest row on the fabric, metres.
Real sew_piece(const Edge& edge, Real from, Real to, Real flare_rad, Real length_m, Real u_offset, GarmentMeshAsset& mesh,
               std::vector<Vec3>& xs, std::vector<Eigen::Vector2f>& uvs, std::vector<Real>& pins) {
    const auto point = [&](Real theta, Real d) {
        const Vec3 top = edge.at(theta);
        Vec3 out(top.x() - edge.axis.x(), 0, top.z() - edge.axis.z());
        out.normalize();
        return Vec3(top + d * (std::sin(flare_rad) * out - std::cos(flare_rad) * Vec3::UnitY()));
    };
    // Across: enough segments for the hem's arc on a body of 16 cm radius (a count from the
    // design alone, so that it does not change with the body's fit, which rounds differently
    // on another CPU).
    const Real nominal_hem_arc = (to - from) * (Real(0.16) + length_m * std::sin(flare_rad));
    const int across = std::max(2, static_cast<int>(std::ceil(nominal_hem_arc / mesh_step_m)));
    const int down = std::max(2, static_cast<int>(std::ceil(length_m / mesh_step_m)));
    const auto first = static_cast<std::uint32_t>(xs.size());
    Real widest = 0;
    for (int j = 0; j <= down; ++j) {
        const Real d = length_m * Real(j) / Real(down);
        std::vector<Vec3> row;
        for (int i = 0; i <= across; ++i) row.push_back(point(from + (to - from) * Real(i) / Real(across), d));
        std::vector<Real> s(1, 0);
        for (int i = 1; i <= across; ++i) s.push_back(s.back() + (row[static_cast<std::size_t>(i)] - row[static_cast<std::size_t>(i - 1)]).norm());
        widest = std::max(widest, s.back());
        for (int i = 0; i <= across; ++i) {
            xs.push_back(row[static_cast<std::size_t>(i)]);
            // Flat on the fabric: across the row by its length on the body, centred.
            uvs.emplace_back(u_offset + (s[static_cast<std::size_t>(i)] - s.back() / 2) * uv_per_m, d * uv_per_m);
            pins.push_back(d <= held_band_m ? Real(1) : Real(0));
        }
    }
    const auto at = [&](int i, int j) { return first + static_cast<std::uint32_t>(j * (across + 1) + i); };
    for (int j = 0; j < down; ++j)
        for (int i = 0; i < across; ++i)
            mesh.indices.insert(mesh.indices.end(), {at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1)});
    return widest;
}

struct PieceSpec {
    Real from, to;  // angles
};

// The fabric's print, woven or printed in the garment's colour: one tile per UV unit (2 m of
// fabric, 512 pixels: 3.9 mm each), repeated.
enum class Print { tartan, stripes, dots, twill };

Image fabric_print(Print print, const Vec3& linear) {
    constexpr int side = 512;
    const auto srgb = [](Real c) { return static_cast<std::uint8_t>(std::lround(255 * std::pow(std::clamp(c, Real(0), Real(1)), Real(1 / 2.2)))); };
    const Vec3 dark = linear * Real(0.35), light(Real(0.85), Real(0.8), Real(0.6));
    Image image;
    image.width = image.height = side;
    image.rgba.resize(std::size_t(side) * side * 4);
    for (int y = 0; y < side; ++y)
        for (int x = 0; x < side; ++x) {
            Vec3 c = linear;
            switch (print) {
                case Print::tartan: {  // bands 5.5 cm wide every 25 cm both ways, a thin light line between
                    const int a = x % 64, b = y % 64;
                    if (a < 14) c = Real(0.5) * (c + dark);
                    if (b < 14) c = Real(0.5) * (c + dark);
                    if ((a >= 38 && a < 40) || (b >= 38 && b < 40)) c = Real(0.4) * c + Real(0.6) * light;
                    break;
                }
                case Print::stripes: {  // along the grain: a 1.6 cm light stripe every 12.5 cm, a dark pinstripe between
                    const int a = x % 32;
                    if (a < 4) c = light;
                    else if (a == 18) c = dark;
                    break;
                }
                case Print::dots: {  // 4.7 cm dots on a 12.5 cm half-drop grid
                    const int row = y / 32, dx = (x + (row % 2) * 16) % 32 - 16, dy = y % 32 - 16;
                    if (dx * dx + dy * dy < 36) c = Vec3(Real(0.9), Real(0.88), Real(0.82));
                    break;
                }
                case Print::twill:  // diagonal ribs 1.6 cm apart
                    if ((x + y) % 4 < 2) c *= Real(1.3);
                    if ((x + y) % 32 < 3) c *= Real(0.7);
                    break;
            }
            std::uint8_t* px = image.rgba.data() + (std::size_t(y) * side + std::size_t(x)) * 4;
            px[0] = srgb(c.x());
            px[1] = srgb(c.y());
            px[2] = srgb(c.z());
            px[3] = 255;
        }
    return image;
}

CutGarment cut(const std::string& name, const Edge& edge, const std::vector<PieceSpec>& pieces, Real flare_deg, Real length_m,
               bool closed, const Vec3& color, Print print, const Affine3& to_model) {
    CutGarment g;
    g.name = name;
    g.panels = static_cast<int>(pieces.size());
    g.closed = closed;
    g.color = color;
    g.mesh.name = name;
    std::vector<Vec3> xs;
    std::vector<Eigen::Vector2f> uvs;
    std::vector<Real> pins;
    Real u = 0;
    for (const PieceSpec& piece : pieces) {
        // Laid out side by side on the fabric, each piece after the ones before, a gap between.
        const std::size_t begin = uvs.size();
        const Real widest = sew_piece(edge, piece.from, piece.to, flare_deg * pi / 180, length_m, 0, g.mesh, xs, uvs, pins);
        for (std::size_t k = begin; k < uvs.size(); ++k) uvs[k].x() += u + Real(0.5) * widest * uv_per_m;
        u += (widest + panel_gap_m) * uv_per_m;
    }
    g.mesh.positions.resize(3, static_cast<Eigen::Index>(xs.size()));
    g.mesh.uvs.resize(2, static_cast<Eigen::Index>(xs.size()));
    g.mesh.pin.resize(static_cast<Eigen::Index>(xs.size()));
    for (std::size_t k = 0; k < xs.size(); ++k) {
        g.mesh.positions.col(static_cast<Eigen::Index>(k)) = to_model * xs[k];
        g.mesh.uvs.col(static_cast<Eigen::Index>(k)) = uvs[k];
        g.mesh.pin[static_cast<Eigen::Index>(k)] = pins[k];
    }
    g.mesh.base_color = fabric_print(print, color);
    return g;
}

}  // namespace

Result<std::vector<CutGarment>> cut_garments(const SceneDescription& scene_in) {
    if (scene_in.characters.empty()) return fail("make-garments: the scene has no character");
    // The body measured through the built-in garments, as they are put on.
    const auto measure = [&](GarmentType type) -> Result<World> {
        SceneDescription scene = scene_in;
        scene.characters.resize(1);
        scene.garments = {GarmentDescription{}};
        scene.garments[0].type = type;
        scene.solver.settle_s = 0;
        return build_world(scene, {});
    };
    auto skirt_world = measure(GarmentType::skirt);
    if (!skirt_world) return std::unexpected(skirt_world.error());
    auto dress_world = measure(GarmentType::dress);
    if (!dress_world) return std::unexpected(dress_world.error());
    const Edge waist = band_of(skirt_world->registry.get<Garment>(skirt_world->garments.at(0)));
    const Edge chest = band_of(dress_world->registry.get<Garment>(dress_world->garments.at(0)));

    Registry& registry = skirt_world->registry;
    const Entity body = skirt_world->characters.at(0);
    const auto* landmarks = registry.try_get<BodyLandmarks>(body);
    const auto* pose = registry.try_get<Skeleton>(body);
    const auto* transform = registry.try_get<Transform>(body);
    if (!landmarks || !pose || !transform || pose->global.empty())
        return fail(scene_in.characters[0].file.string() + ": no body landmarks (shoulders) to cut a cape for");
    // The shoulders: where the upper arms meet the trunk: of the arm chain's first two
    // joints (a clavicle's, by the neck, then the upper arm's; or the upper arm's, then the
    // elbow), the one farther out that is level with the first.
    const auto shoulder = [&](const LimbChain& arm) -> std::optional<Vec3> {
        if (arm.root < 0) return std::nullopt;
        const auto joint = [&](int bone) { return Vec3(transform->matrix() * Vec3(pose->global.at(static_cast<std::size_t>(bone)).translation())); };
        const Vec3 root = joint(arm.root);
        if (arm.middle < 0) return root;
        const Vec3 next = joint(arm.middle);
        const auto out = [&](const Vec3& p) { return std::hypot(p.x() - transform->position.x(), p.z() - transform->position.z()); };
        return std::abs(next.y() - root.y()) < Real(0.1) && out(next) > out(root) ? next : root;
    };
    const auto left_joint = shoulder(landmarks->left_arm), right_joint = shoulder(landmarks->right_arm);
    if (!left_joint || !right_joint) return fail(scene_in.characters[0].file.string() + ": no arms to hang a cape from");
    const Vec3 left = *left_joint, right = *right_joint;
    const Affine3 to_model(transform->matrix().inverse());

    // The cape's top edge: half an ellipse over the shoulders, round the back of the neck.
    const Vec3 centre = Real(0.5) * (left + right);
    const Real half_width = Real(0.5) * (left - right).norm() + Real(0.04), depth = Real(0.13), above = Real(0.05);
    const Edge shoulders{[=](Real theta) { return Vec3(centre + Vec3(half_width * std::sin(theta), above, depth * std::cos(theta))); }, centre};

    std::vector<CutGarment> out;
    const Real q = pi / 2;
    out.push_back(cut("flared_skirt", waist, {{-q / 2, q / 2}, {q / 2, 3 * q / 2}, {3 * q / 2, 5 * q / 2}, {5 * q / 2, 7 * q / 2}}, 22,
                      Real(0.55), true, Vec3(0.55f, 0.08f, 0.12f), Print::tartan, to_model));
    out.push_back(cut("wrap_skirt", waist, {{pi / 10, 2 * pi - pi / 10}}, 14, Real(0.6), false, Vec3(0.2f, 0.45f, 0.25f), Print::stripes,
                      to_model));
    out.push_back(cut("panel_dress", chest, {{-q, q}, {q, 3 * q}}, 10, Real(1.05), true, Vec3(0.15f, 0.3f, 0.7f), Print::dots, to_model));
    out.push_back(cut("cape", shoulders, {{q, 3 * q}}, 10, Real(0.85), false, Vec3(0.35f, 0.12f, 0.45f), Print::twill, to_model));
    return out;
}

}  // namespace drape
