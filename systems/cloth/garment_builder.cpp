// Garment builders (method §3.2, §3.5); placement rules in garment_builder.hpp.
#include "drape/systems/cloth/garment_builder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>

#include "drape/components/body_landmarks.hpp"
#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/components/transform.hpp"
#include "drape/systems/character/body_landmarks.hpp"
#include "drape/systems/character/trunk_skin.hpp"
#include "drape/systems/cloth/body.hpp"
#include "drape/systems/cloth/collision.hpp"
#include "drape/systems/cloth/garment_parameters.hpp"
#include "drape/systems/cloth/garment_parts.hpp"
#include "drape/systems/cloth/garment_step.hpp"
#include "drape/systems/cloth/pins.hpp"

namespace drape {
namespace {

std::string field(std::string_view prefix, std::string_view name) {
    return std::string(prefix) + "." + std::string(name);
}

// A number as a user would write it (0.55, 1e+30, nan); std::to_string prints 0.000000 for 1e-30.
std::string number(Real v) {
    std::ostringstream s;
    s << v;
    return s.str();
}
// In (0, hi] (or [0, hi] when zero is allowed), finite: a rectangle's sizes. (The skirt's
// and the dress's ranges are in the garment parameter table.) Beyond them float arithmetic,
// not the cloth, decides what happens.
bool in_range(Real v, Real hi, bool zero_allowed = false) {
    return std::isfinite(v) && (zero_allowed ? v >= 0 : v > 0) && v <= hi;
}

Result<void> validate_grid(std::string_view p, int lines, int per_line, int stride, bool closed) {
    if (lines < 2 || lines > 4096) return fail(field(p, "warp_lines") + ": must be in [2, 4096], got " + std::to_string(lines));
    if (per_line < 2 || per_line > 4096)
        return fail(field(p, "particles_per_line") + ": must be in [2, 4096], got " + std::to_string(per_line));
    if (static_cast<long long>(lines) * per_line > max_garment_particles)
        return fail(field(p, "warp_lines") + " x " + field(p, "particles_per_line") + ": must be at most " +
                    std::to_string(max_garment_particles) + " particles, got " + std::to_string(lines) + " x " +
                    std::to_string(per_line) + " = " + std::to_string(static_cast<long long>(lines) * per_line));
    if (stride < 1 || stride >= lines)
        return fail(field(p, "weft_stride") + ": must be in [1, warp_lines), got " + std::to_string(stride));
    if (closed && lines % stride != 0)
        return fail(field(p, "warp_lines") + ": must be a multiple of " + field(p, "weft_stride") + " (" +
                    std::to_string(lines) + " % " + std::to_string(stride) + " != 0)");
    if (!closed && (lines - 1) % stride != 0)
        return fail(field(p, "warp_lines") + ": warp_lines - 1 must be a multiple of " + field(p, "weft_stride") +
                    " so that the last line is layer 1 (" + std::to_string(lines - 1) + " % " + std::to_string(stride) +
                    " != 0)");
    return {};
}

// One row of the parameter table against its value: "skirt.length_m: must be in (0, 10] m, got -1".
Result<void> check(const GarmentParameterSpec& spec, double value, std::string_view p, std::string_view field_name) {
    if (spec.range.contains(value)) return {};
    std::string message = field(p, field_name) + ": must be in " + spec.range.text();
    if (!spec.unit.empty()) message += " " + std::string(spec.unit);
    message += ", got ";
    message += spec.kind == ParameterKind::integer ? std::to_string(static_cast<long long>(value)) : number(static_cast<Real>(value));
    return fail(message);
}

// Particle-order positions from grid-order positions.
Matrix3X to_particle_order(const Fabric& t, const Matrix3X& grid_positions) {
    Matrix3X x(3, grid_positions.cols());
    for (Eigen::Index k = 0; k < grid_positions.cols(); ++k) x.col(t.grid[static_cast<std::size_t>(k)]) = grid_positions.col(k);
    return x;
}

Garment make_instance(std::shared_ptr<const Fabric> fabric, Matrix3X x, const ClothMaterial& material,
                      ClothModel model, ClothIntegrator integrator, CollisionMode collision, const Vec3& color) {
    Garment g;
    const Eigen::Index n = x.cols();
    g.fabric = std::move(fabric);
    g.state.x = std::move(x);
    g.state.v = Matrix3X::Zero(3, n);
    g.state.inv_mass = (material.areal_density_kg_m2 * g.fabric->area_m2).cwiseInverse();
    g.config.material = material;
    g.config.model = model;
    g.config.integrator = integrator;
    g.config.collision = collision;
    g.config.color = color;
    return g;
}

}  // namespace

GarmentConfig garment_config(const TubeParams& p) {
    GarmentConfig c;
    c.model = p.model;
    c.integrator = p.integrator;
    c.collision = p.collision;
    c.material = p.material;
    c.inertia = InertiaScales{p.inertia_linear, p.inertia_angular, p.inertia_max_linear_m_s2, p.inertia_max_fall_m_s2};
    c.max_distance_share = p.max_distance_share;
    c.max_distance_on_skin = p.max_distance_on_skin != 0;
    c.color = p.color;
    return c;
}

namespace {

// Vertical half extent of an ellipsoid (its axis-aligned box).
Real half_height(const EllipsoidFrame& f) { return (f.rotation * f.radii_m.asDiagonal()).row(1).norm(); }

// Distance along the horizontal ray o + t d at which it leaves the ellipsoid (<0: misses).
Real ray_exit(const EllipsoidFrame& f, const Vec3& o, const Vec3& d) {
    const Vec3 oo = f.to_unit * (o - f.center);
    const Vec3 dd = f.to_unit * d;
    const Real a = dd.squaredNorm(), b = 2 * oo.dot(dd), c = oo.squaredNorm() - 1;
    const Real disc = b * b - 4 * a * c;
    if (disc < 0 || a <= 0) return -1;
    return (-b + std::sqrt(disc)) / (2 * a);
}

// How far the ellipsoid reaches from o in direction d (|d| = 1): its support, d . (c - o)
// + |diag(r) R^T d|.
Real support_distance(const EllipsoidFrame& f, const Vec3& o, const Vec3& d) {
    return d.dot(f.center - o) + f.radii_m.cwiseProduct(f.rotation.transpose() * d).norm();
}

// Half the thinner leg's thickness at height y: per leg, the thickest of its ellipsoids
// that the level plane at y crosses (its smallest radius; the thigh, the knee and the shin
// overlap there), the thinner of the legs. Radii, not the slices' widths: near an
// ellipsoid's tip (a lifted foot, a bent knee) a slice is as thin as it likes. A leg is the
// ellipsoids on one chain of leg bones (`leg_bone`: the collider's bone on a leg, -1 off
// the legs), grouped by their topmost leg bone in `skeleton`; without a skeleton each
// ellipsoid stands alone. 0 where no leg reaches y.
Real hem_leg_half_width(std::span<const EllipsoidFrame> frames, std::span<const int> leg_bone, const SkeletonAsset* skeleton, Real y) {
    const auto top_of = [&](int bone) {
        for (int up = bone; up >= 0 && static_cast<std::size_t>(up) < skeleton->size(); up = skeleton->parents[static_cast<std::size_t>(up)])
            if (std::find(leg_bone.begin(), leg_bone.end(), up) != leg_bone.end()) bone = up;
        return bone;
    };
    std::vector<std::pair<int, Real>> legs;  // topmost leg bone, thickest piece's smallest radius
    for (std::size_t e = 0; e < frames.size(); ++e) {
        const EllipsoidFrame& f = frames[e];
        if (leg_bone[e] < 0 || !f.active || std::abs(f.center.y() - y) >= half_height(f)) continue;
        const Real r = f.radii_m.minCoeff();
        const int top = skeleton ? top_of(leg_bone[e]) : -1 - static_cast<int>(e);
        auto leg = std::find_if(legs.begin(), legs.end(), [&](const auto& l) { return l.first == top; });
        if (leg == legs.end()) legs.emplace_back(top, r);
        else leg->second = std::max(leg->second, r);
    }
    Real thinnest = 0;
    for (const auto& [top, r] : legs) thinnest = thinnest == 0 ? r : std::min(thinnest, r);
    return thinnest;
}

// A point (model space) bound to the skin at its closest point there (trunk_skin.hpp), by the
// four strongest weights of that point, normalised: a skinned binding, its particle unset.
// Nothing where the skin gives no weight or the bones' blend cannot be inverted.
std::optional<PinBinding> bind_to_skin_surface(const TrunkSkin& skin, const MeshAsset& mesh, const std::vector<Affine3>& skinning,
                                               const Vec3& model) {
    const std::vector<BoneInfluence> influences = trunk_influences(skin, mesh, model.cast<double>());
    double total = 0;
    for (std::size_t i = 0; i < influences.size() && i < 4; ++i) total += influences[i].weight;
    if (!(total > 0)) return std::nullopt;
    PinBinding b;
    for (std::size_t i = 0; i < influences.size() && i < 4; ++i) {
        b.bones[static_cast<Eigen::Index>(i)] = influences[i].bone;
        b.weights[static_cast<Eigen::Index>(i)] = static_cast<Real>(influences[i].weight / total);
    }
    const Affine3 m = blend_skinning(skinning, b.bones, b.weights);
    if (!(std::abs(m.linear().determinant()) > Real(1e-8))) return std::nullopt;
    b.kind = PinKind::skinned;
    b.local = m.inverse() * model;
    return b;
}

// Binds pinned particle p (world position x) to the body (method §3.5).
PinBinding bind_pin(const Registry& registry, Entity character, const std::vector<Entity>& colliders,
                    std::span<const EllipsoidFrame> frames, const TrunkSkin* trunk, const MeshAsset& mesh, std::uint32_t p,
                    const Vec3& x) {
    PinBinding pin;
    pin.particle = p;
    // Nearest collider in unit-sphere terms (the body part the pin sits on).
    std::size_t nearest = 0;
    Real best = std::numeric_limits<Real>::infinity();
    for (std::size_t e = 0; e < frames.size(); ++e) {
        if (!frames[e].active) continue;
        const Real d = to_unit_sphere(frames[e], x).norm();
        if (d < best) { best = d; nearest = e; }
    }

    const auto* skeleton = registry.try_get<Skeleton>(character);
    const auto* transform = registry.try_get<Transform>(character);
    const bool can_skin = skeleton && skeleton->asset && !skeleton->skinning.empty() &&
                          skeleton->skinning.size() == skeleton->asset->size();
    if (can_skin) {
        const Affine3 to_model = transform ? transform->matrix().inverse() : Affine3::Identity();
        const Vec3 model = to_model * x;
        Vec4i bones = Vec4i::Zero();
        Vec4 weights = Vec4::Zero();
        bool found = false;
        if (trunk) {
            // PinWeights::skin_surface: at the closest point of the trunk's skin.
            if (std::optional<PinBinding> on_skin = bind_to_skin_surface(*trunk, mesh, skeleton->skinning, model)) {
                on_skin->particle = p;
                return *on_skin;
            }
        }
        const auto* skin = registry.try_get<SkinnedMesh>(character);
        if (!trunk && skin && skin->mesh && skin->mesh->vertex_count() > 0) {
            // PinWeights::nearest_vertex (and a skin without faces): the weights of the nearest
            // skin vertex at the current pose (linear blend skinning).
            // The fitting zone is on the trunk (method §3.5): on a body with landmarks only
            // skin carried mostly by the pelvis and spine counts, and only those bones' share
            // of its weights, so that a hand hanging at the hip or a thigh does not take the
            // waistband with it.
            const auto* landmarks = registry.try_get<BodyLandmarks>(character);
            std::vector<bool> on_trunk_bone;
            if (landmarks && landmarks->pelvis_bone >= 0) {
                on_trunk_bone.assign(skeleton->skinning.size(), false);
                for (int bone : landmarks->spine)
                    if (bone >= 0 && static_cast<std::size_t>(bone) < on_trunk_bone.size()) on_trunk_bone[static_cast<std::size_t>(bone)] = true;
                if (static_cast<std::size_t>(landmarks->pelvis_bone) < on_trunk_bone.size())
                    on_trunk_bone[static_cast<std::size_t>(landmarks->pelvis_bone)] = true;
                if (landmarks->head_bone >= 0 && static_cast<std::size_t>(landmarks->head_bone) < on_trunk_bone.size())
                    on_trunk_bone[static_cast<std::size_t>(landmarks->head_bone)] = false;
            }
            const MeshAsset& skin_mesh = *skin->mesh;
            Real best_d = std::numeric_limits<Real>::infinity();
            for (std::size_t v = 0; v < skin_mesh.vertex_count(); ++v) {
                const Eigen::Index vi = static_cast<Eigen::Index>(v);
                const Vec4i b = skin_mesh.bone_indices.col(vi);
                Vec4 w = skin_mesh.bone_weights.col(vi);
                bool ok = true;
                for (int i = 0; i < 4; ++i)
                    if (w[i] != 0 && (b[i] < 0 || static_cast<std::size_t>(b[i]) >= skeleton->skinning.size())) ok = false;
                if (!ok) continue;
                if (!on_trunk_bone.empty()) {
                    Vec4 on_trunk = Vec4::Zero();
                    for (int i = 0; i < 4; ++i)
                        if (w[i] != 0 && on_trunk_bone[static_cast<std::size_t>(b[i])]) on_trunk[i] = w[i];
                    const Real share = on_trunk.sum();
                    if (share < Real(0.5) * w.sum()) continue;
                    w = on_trunk / share;
                }
                const Vec3 posed = blend_skinning(skeleton->skinning, b, w) * Vec3(skin_mesh.bind_positions.col(vi));
                const Real d = (posed - model).squaredNorm();
                if (d < best_d) { best_d = d; bones = b; weights = w; found = true; }
            }
        }
        if (!found && !colliders.empty()) {
            const auto* c = registry.try_get<EllipsoidCollider>(colliders[nearest]);
            if (c && c->bone >= 0 && static_cast<std::size_t>(c->bone) < skeleton->skinning.size()) {
                bones = Vec4i(c->bone, 0, 0, 0);
                weights = Vec4(1, 0, 0, 0);
                found = true;
            }
        }
        if (found) {
            const Affine3 m = blend_skinning(skeleton->skinning, bones, weights);
            if (std::abs(m.linear().determinant()) > Real(1e-8)) {
                pin.kind = PinKind::skinned;
                pin.bones = bones;
                pin.weights = weights;
                pin.local = m.inverse() * model;
                return pin;
            }
        }
    }
    if (!colliders.empty() && std::isfinite(best)) {
        pin.kind = PinKind::collider;
        pin.collider = static_cast<std::int32_t>(nearest);
        pin.local = unit_to_world(frames[nearest]).inverse() * x;
        return pin;
    }
    pin.kind = PinKind::world;
    pin.local = x;
    return pin;
}

// GarmentConfig::max_distance_on_skin: each free particle's rest place bound to the skin of
// the trunk and legs (the arms left out: a hand hanging at the hip does not carry a skirt) at
// its closest point there, by that point's weights, as a skin_surface pin is. Nothing (the
// anchor carries the spheres) without a skinned body or where a binding cannot be inverted.
void bind_rest_to_skin(const Registry& registry, Garment& g) {
    g.body.rest_on_skin.clear();
    if (!g.config.max_distance_on_skin) return;
    const auto* skin = registry.try_get<SkinnedMesh>(g.body.character);
    const auto* skeleton = registry.try_get<Skeleton>(g.body.character);
    if (!skin || !skin->mesh || !skeleton || !skeleton->asset || skeleton->skinning.size() != skeleton->asset->size()) return;
    const std::optional<TrunkSkin> body = trunk_skin(*skin->mesh, *skeleton->asset, registry.try_get<BodyLandmarks>(g.body.character),
                                                     skeleton->skinning, /*with_legs=*/true);
    if (!body) return;
    const auto* transform = registry.try_get<Transform>(g.body.character);
    const Affine3 to_model = transform ? transform->matrix().inverse() : Affine3::Identity();
    const Eigen::Index n = g.state.x.cols();
    std::vector<PinBinding> bound(static_cast<std::size_t>(n));
    for (Eigen::Index p = 0; p < n; ++p) {
        PinBinding& b = bound[static_cast<std::size_t>(p)];
        b.particle = static_cast<std::uint32_t>(p);
        if (g.state.inv_mass[p] == 0) continue;  // pinned: no sphere
        std::optional<PinBinding> on_skin = bind_to_skin_surface(*body, *skin->mesh, skeleton->skinning, to_model * Vec3(g.state.x.col(p)));
        if (!on_skin) return;
        b = *on_skin;
        b.particle = static_cast<std::uint32_t>(p);
    }
    g.body.rest_on_skin = std::move(bound);
}

// Pins the particles `pinned` marks (grid order, line * m + row), pushes the rest out of
// the colliders, records the rest shape, and adds the garment to the registry.
Result<Entity> finish(Registry& registry, Garment g, const std::vector<std::uint8_t>& pinned, PinWeights pin_weights) {
    const Fabric& t = *g.fabric;
    GarmentSolver solver;
    GarmentState& state = g.state;
    update_frames(registry, g.body, solver.frames, 1);
    // PinWeights::skin_surface: the trunk's skin as the character stands, once for every pin.
    const auto* skin = registry.try_get<SkinnedMesh>(g.body.character);
    const auto* skeleton = registry.try_get<Skeleton>(g.body.character);
    const MeshAsset no_mesh;
    const MeshAsset& mesh = skin && skin->mesh ? *skin->mesh : no_mesh;
    std::optional<TrunkSkin> trunk;
    if (pin_weights == PinWeights::skin_surface && skeleton && skeleton->asset && skeleton->skinning.size() == skeleton->asset->size())
        trunk = trunk_skin(mesh, *skeleton->asset, registry.try_get<BodyLandmarks>(g.body.character), skeleton->skinning);
    for (std::size_t k = 0; k < t.grid.size(); ++k) {
        if (!pinned.at(k)) continue;
        const std::uint32_t p = t.grid[k];
        state.inv_mass[p] = 0;
        state.pins.push_back(bind_pin(registry, g.body.character, g.body.colliders, solver.frames, trunk ? &*trunk : nullptr, mesh, p,
                                      state.x.col(p)));
    }
    for (const PinBinding& pin : state.pins)
        if (auto at = evaluate_pin(registry, g, pin)) state.x.col(pin.particle) = *at;
    prepare_solver(g, solver);
    tuck_under_limbs(registry, g.body, solver.frames, state.x, state.inv_mass);
    std::vector<std::uint64_t> last;
    for (int pass = 0; pass < 4; ++pass) collide_particles(state.x, state.v, state.inv_mass, solver.frames, nullptr, last);
    state.v.setZero();
    const Affine3 anchor = anchor_frame(solver.frames, g.body.anchor);
    g.body.rest_local = anchor.inverse(Eigen::Isometry) * state.x;
    bind_rest_to_skin(registry, g);
    update_pin_targets(registry, g, solver, true);
    if (!state.x.allFinite()) return fail(std::string("garment placement produced non-finite positions"));
    const Entity e = registry.create();
    registry.emplace<Garment>(e, std::move(g));
    registry.emplace<GarmentSolver>(e, std::move(solver));
    return e;
}

Result<Entity> attach_tube(Registry& registry, Entity character, std::string_view name, const TubeParams& s) {
    const std::string p(name);
    if (!registry.valid(character)) return fail(p + ": the character entity is not alive");
    const std::vector<Entity> colliders = character_colliders(registry, character);
    if (colliders.empty()) return fail(p + ": the character has no ellipsoid colliders");
    if (colliders.size() > 64) return fail(p + ": the character has " + std::to_string(colliders.size()) +
                                           " colliders; a garment handles at most 64");
    std::vector<EllipsoidFrame> frames;
    bool placed = false;
    std::vector<std::uint8_t> limb;  // arms, hands, head: never part of the body's outline
    std::vector<int> leg_bone;       // per collider: its bone on a leg, else -1
    for (Entity e : colliders) {
        const auto& c = registry.get<EllipsoidCollider>(e);
        placed = placed || c.placed || c.initialised;
        frames.push_back(make_ellipsoid_frame(c.world));
        limb.push_back(hangs_outside_garments(c.region));
        leg_bone.push_back(is_leg(c.region) ? c.bone : -1);
    }
    if (!placed) return fail(p + ": the character's colliders have not been placed yet (run the collider system once)");

    // Body height and axis: from the landmarks when the character has them, else from the
    // colliders (their vertical extent; the mean of their centres).
    Real bottom = std::numeric_limits<Real>::infinity(), top = -bottom;
    Vec3 axis = Vec3::Zero();
    int active = 0;
    for (const EllipsoidFrame& f : frames) {
        if (!f.active) continue;
        bottom = std::min(bottom, f.center.y() - half_height(f));
        top = std::max(top, f.center.y() + half_height(f));
        axis += f.center;
        ++active;
    }
    if (active == 0) return fail(p + ": the character's colliders are degenerate (zero radii)");
    axis /= Real(active);
    Real height = top - bottom;
    std::optional<Real> landmark_y;
    const auto* landmarks = registry.try_get<BodyLandmarks>(character);
    const auto* pose = registry.try_get<Skeleton>(character);
    const auto* transform = registry.try_get<Transform>(character);
    if (landmarks && pose && transform && !pose->global.empty()) {
        const BodyPoint& at = s.ring_at == RingPlace::waist ? landmarks->waist.center : landmarks->arms_meet_trunk;
        const Vec3 ring = landmark_world(at, *pose, *transform);
        height = landmarks->height_m * transform->scale;
        bottom = (transform->matrix() * Vec3(0, landmarks->floor_m, 0)).y();  // an upright character
        axis = ring;
        // Under the arms: a little lower, so that the arms' skin clears the cloth.
        landmark_y = ring.y() - (s.ring_at == RingPlace::under_arms ? Real(0.02) * height : Real(0));
    }
    Real ring_y = bottom + fallback_ring_height_fraction(s.ring_at) * height;
    if (s.ring_height_m > 0) ring_y = bottom + s.ring_height_m;
    else if (s.ring_height_fraction > 0) ring_y = bottom + s.ring_height_fraction * height;
    else if (landmark_y) ring_y = *landmark_y;
    const Vec3 origin(axis.x(), ring_y, axis.z());

    // Outline colliders: cross the ring height, near the axis.
    std::vector<std::size_t> outline;
    for (std::size_t e = 0; e < frames.size(); ++e) {
        const EllipsoidFrame& f = frames[e];
        if (!f.active || limb[e] || std::abs(f.center.y() - ring_y) >= half_height(f)) continue;
        const Vec3 off(f.center.x() - axis.x(), 0, f.center.z() - axis.z());
        if (off.norm() > s.torso_radius_fraction * height) continue;
        outline.push_back(e);
    }
    if (outline.empty())
        return fail(p + ": no collider crosses the ring height " + number(ring_y) + " m near the body axis");

    // The ring's radius toward d (level, unit): where the ray leaves the body outline, plus
    // the ease; 0 where the outline does not surround the axis.
    const auto ring_radius = [&](const Vec3& d) {
        Real r = -1;
        for (std::size_t e : outline) r = std::max(r, ray_exit(frames[e], origin, d));
        // Between two legs hugged apart (a ring below the crotch) a ray may pass every
        // collider: the line then stands on the body's hull, as far as the colliders reach.
        if (r <= 0)
            for (std::size_t e : outline) r = std::max(r, support_distance(frames[e], origin, d));
        return r <= 0 ? Real(0) : r + s.ease_m;
    };
    const auto direction = [](Real theta) { return Vec3(std::sin(theta), 0, std::cos(theta)); };
    const int m = s.particles_per_line;
    const Real flare_rad = s.flare_deg * std::numbers::pi_v<Real> / 180;
    // The hem above the ankles: a dress made for one body must not reach into the feet (or
    // through the floor) of a shorter one.
    Real length = s.length_m;
    if (s.hem_clearance_fraction > 0) {
        const Real drop = ring_y - (bottom + s.hem_clearance_fraction * height);
        if (drop <= 0)
            return fail(p + ".hem_clearance_fraction: the ring at " + number(ring_y - bottom) + " m is not above the hem's lowest height " +
                        number(s.hem_clearance_fraction * height) + " m");
        length = std::min(length, drop / std::cos(flare_rad));
    }
    const Real step = length / Real(m - 1);
    // The line toward d (level, unit) from the ring's radius r there: `put(row, point)` for
    // each row. Down the cone, but never closer to the axis than the body below the ring
    // (hips, thighs, bust) plus the ease: the rest shape must fit over the body, or the cloth
    // would hang stretched over it. Once widened, the line keeps its width below.
    const auto place_line = [&](const Vec3& d, Real r, auto&& put) {
        Real widest = r;
        for (int row = 0; row < m; ++row) {
            const Real along = step * Real(row);
            const Vec3 centre = origin - Vec3::UnitY() * (along * std::cos(flare_rad));
            Real need = 0;
            for (std::size_t e = 0; e < frames.size(); ++e) {
                const EllipsoidFrame& f = frames[e];
                if (!f.active || limb[e] || std::abs(f.center.y() - centre.y()) >= half_height(f)) continue;
                const Vec3 off(f.center.x() - axis.x(), 0, f.center.z() - axis.z());
                if (off.norm() > s.torso_radius_fraction * height) continue;  // arms, hands
                need = std::max(need, ray_exit(f, centre, d) + s.ease_m);
            }
            widest = std::max({widest, r + along * std::sin(flare_rad), need});
            put(row, centre + d * widest);
        }
    };
    const std::string not_surrounded = p + ": the body outline at the ring height does not surround the axis";
    // Perimeters of the ring and of the hem, sampled at ring_samples directions.
    constexpr int ring_samples = 64;
    Real ring_perimeter = 0, hem_perimeter = 0;
    Vec3 last_ring, last_hem;
    for (int k = 0; k <= ring_samples; ++k) {
        const Vec3 d = direction(Real(2) * std::numbers::pi_v<Real> * Real(k % ring_samples) / Real(ring_samples));
        const Real r = ring_radius(d);
        if (r <= 0) return fail(not_surrounded);
        Vec3 hem = Vec3::Zero();
        place_line(d, r, [&](int row, const Vec3& at) { if (row == m - 1) hem = at; });
        const Vec3 ring = origin + d * r;
        if (k > 0) {
            ring_perimeter += (ring - last_ring).norm();
            hem_perimeter += (hem - last_hem).norm();
        }
        last_ring = ring;
        last_hem = hem;
    }
    // More lines where they would stand too far apart (a multiple of weft_stride, never
    // fewer than warp_lines): round a wider body, at most line_spacing_m apart at the ring;
    // at the hem, layer-1 lines at most hem_spacing_leg_widths times the thinner leg's width
    // there apart, so that a hem line cannot straddle a leg (hem_leg_half_width).
    int n = s.warp_lines;
    const auto at_least = [&](double lines, std::string_view key, const std::string& why) -> Result<void> {
        const double needed = std::ceil(lines / s.weft_stride) * s.weft_stride;
        if (!(needed <= 4096 && needed * s.particles_per_line <= max_garment_particles))
            return fail(field(p, key) + ": " + why + " needs " + number(needed) + " lines; at most 4096 lines and " +
                        std::to_string(max_garment_particles) + " particles in all");
        n = std::max(n, static_cast<int>(needed));
        return {};
    };
    if (s.line_spacing_m > 0)
        if (auto ok = at_least(double(ring_perimeter) / s.line_spacing_m, "line_spacing_m",
                               number(s.line_spacing_m) + " m round a ring of " + number(ring_perimeter) + " m");
            !ok)
            return std::unexpected(ok.error());
    const Real hem_y = origin.y() - length * std::cos(flare_rad);
    const Real leg_width = 2 * hem_leg_half_width(frames, leg_bone, pose ? pose->asset.get() : nullptr, hem_y);
    if (s.hem_spacing_leg_widths > 0 && leg_width > 0)
        if (auto ok = at_least(double(hem_perimeter) / (s.hem_spacing_leg_widths * leg_width) * s.weft_stride, "hem_spacing_leg_widths",
                               number(s.hem_spacing_leg_widths) + " x a leg " + number(leg_width) + " m wide round a hem of " +
                                   number(hem_perimeter) + " m");
            !ok)
            return std::unexpected(ok.error());
    Matrix3X grid(3, n * m);
    for (int line = 0; line < n; ++line) {
        const Vec3 d = direction(Real(2) * std::numbers::pi_v<Real> * Real(line) / Real(n));
        const Real r = ring_radius(d);
        if (r <= 0) return fail(not_surrounded);
        place_line(d, r, [&](int row, const Vec3& at) { grid.col(line * m + row) = at; });
    }
    auto topology = build_grid_topology(n, m, s.weft_stride, true, grid, name);
    if (!topology) return std::unexpected(topology.error());
    Garment g = make_instance(*topology, to_particle_order(**topology, grid), s.material, s.model, s.integrator, s.collision, s.color);
    g.config = garment_config(s);
    g.body.character = character;
    // Anchor: the outline collider nearest the axis at the ring height (pelvis, chest).
    std::size_t anchor = outline.front();
    for (std::size_t e : outline)
        if ((frames[e].center - origin).norm() < (frames[anchor].center - origin).norm()) anchor = e;
    // Hung from under the arms, the garment has the upper arms outside it: they hang against
    // the chest, their ellipsoids overlap it, and cloth between the two cannot be outside
    // both. It does not collide with them: it stays on the chest, under the arm.
    // With thin_trunk_piece_m, nor with the trunk's pieces thinner than that (docs/cloth.md,
    // "Thin trunk pieces"): standing between two neighbouring particles, each pushed out to
    // its own side, they hold the cloth open.
    for (std::size_t e = 0; e < colliders.size(); ++e) {
        const BodyRegion region = registry.get<EllipsoidCollider>(colliders[e]).region;
        if (s.ring_at == RingPlace::under_arms && region == BodyRegion::upper_arm) continue;
        if (s.thin_trunk_piece_m > 0 && e != anchor && (region == BodyRegion::torso || region == BodyRegion::pelvis) &&
            frames[e].radii_m.minCoeff() <= s.thin_trunk_piece_m)
            continue;
        if (e == anchor) g.body.anchor = static_cast<std::int32_t>(g.body.colliders.size());
        g.body.colliders.push_back(colliders[e]);
    }
    std::vector<std::uint8_t> pinned(g.fabric->grid.size(), 0);
    for (int line = 0; line < n; ++line)
        for (int row = 0; row < s.fitting_rows; ++row) pinned[static_cast<std::size_t>(line * m + row)] = 1;
    return finish(registry, std::move(g), pinned, s.pin_weights);
}

}  // namespace

Real fallback_ring_height_fraction(RingPlace place) noexcept {
    return place == RingPlace::waist ? Real(0.58) : Real(0.72);
}

Result<void> validate(const ClothMaterial& m, std::string_view p) {
    for (const GarmentParameterSpec& spec : garment_parameters())
        if (spec.in_material())
            if (auto ok = check(spec, spec.get(m), p, spec.name); !ok) return ok;
    return {};
}

Result<void> validate(const TubeParams& s, std::string_view garment) {
    for (const GarmentParameterSpec& spec : garment_parameters())
        if (auto ok = check(spec, spec.get(s), garment, spec.field()); !ok) return ok;
    // What one row cannot say: the grid as a whole, and the pins within it.
    if (auto ok = validate_grid(garment, s.warp_lines, s.particles_per_line, s.weft_stride, true); !ok) return ok;
    if (s.fitting_rows >= s.particles_per_line)
        return fail(field(garment, "fitting_rows") + ": must be in [1, particles_per_line), got " + std::to_string(s.fitting_rows));
    return {};
}

Result<void> validate(const RectangleParams& r) {
    if (auto ok = validate_grid("rectangle", r.warp_lines, r.particles_per_line, r.weft_stride, false); !ok) return ok;
    if (!in_range(r.width_m, 100)) return fail("rectangle.width_m: must be in (0, 100] m, got " + number(r.width_m));
    if (!in_range(r.length_m, 100)) return fail("rectangle.length_m: must be in (0, 100] m, got " + number(r.length_m));
    // Beyond 10 km a float position keeps less than a millimetre.
    if (!r.origin.allFinite() || r.origin.cwiseAbs().maxCoeff() > Real(1e4))
        return fail("rectangle.origin: must be finite and within 10 km of the world origin");
    return validate(r.material, "rectangle.material");
}

Result<std::shared_ptr<const Fabric>> build_grid_topology(int lines_in, int per_line_in, int stride_in,
                                                                   bool closed, const Matrix3X& pos,
                                                                   std::string_view p) {
    if (auto ok = validate_grid(p, lines_in, per_line_in, stride_in, closed); !ok) return std::unexpected(ok.error());
    const auto n = static_cast<std::uint32_t>(lines_in), m = static_cast<std::uint32_t>(per_line_in),
               stride = static_cast<std::uint32_t>(stride_in);
    if (pos.cols() != static_cast<Eigen::Index>(n * m))
        return fail(std::string(p) + ": " + std::to_string(pos.cols()) + " positions for a " + std::to_string(n) + " x " +
                    std::to_string(m) + " grid");
    if (!pos.allFinite()) return fail(std::string(p) + ": non-finite rest positions");

    auto t = std::make_shared<Fabric>();
    t->warp_lines = n;
    t->particles_per_line = m;
    t->weft_stride = stride;
    t->closed = closed;
    const auto is_layer1 = [&](std::uint32_t line) { return line % stride == 0; };
    const auto gi = [&](std::uint32_t line, std::uint32_t row) { return line * m + row; };

    // Particle order: layer 1 first (one contiguous block to integrate), then layer 2 by the
    // lines' place between their layer-1 neighbours (line % stride); within each block band
    // by band of neighbouring lines (garment_parts.hpp; one band below 10,000 particles),
    // within a band row by row, its lines side by side. A row of warp springs of one band,
    // or of weft springs between two blocks, then joins consecutive particles to consecutive
    // particles: the solver takes each such row as one strip of independent springs, rows
    // from the fitting zone down (constraints.hpp).
    t->grid.assign(n * m, 0);
    t->layer.assign(n * m, 0);
    t->line_bands = part_count(n, m);
    const std::vector<std::uint32_t> edges = line_band_edges(n, t->line_bands);
    std::uint32_t next = 0;
    for (std::uint32_t offset = 0; offset < stride; ++offset)
        for (std::uint32_t band = 0; band < t->line_bands; ++band)
            for (std::uint32_t row = 0; row < m; ++row)
                for (std::uint32_t line = offset; line < n; line += stride) {
                    if (line_band_of(edges, line) != band) continue;
                    t->grid[gi(line, row)] = next;
                    t->layer[next++] = static_cast<std::uint8_t>(offset == 0 ? 1 : 2);
                }
    t->layer1_count = static_cast<std::uint32_t>(std::count(t->layer.begin(), t->layer.end(), 1));

    const auto at = [&](std::uint32_t line, std::uint32_t row) { return t->grid[gi(line, row)]; };
    const auto rest = [&](std::uint32_t a_line, std::uint32_t a_row, std::uint32_t b_line, std::uint32_t b_row) {
        return (pos.col(gi(b_line, b_row)) - pos.col(gi(a_line, a_row))).norm();
    };
    const std::uint32_t weft_lines = closed ? n : n - 1;  // line -> line + 1 pairs
    std::string degenerate;
    const auto add = [&](SpringPhase& phase, std::uint32_t al, std::uint32_t ar, std::uint32_t bl, std::uint32_t br) {
        const Real r = rest(al, ar, bl, br);
        if (!(r > Real(1e-6))) degenerate = "two neighbouring particles coincide at rest";
        phase.add(at(al, ar), at(bl, br), r);
    };
    // Every phase line by line, rows from the fitting zone (row 0) outward: a line's springs
    // are then runs of consecutive particles, which the solver takes a strip at a time
    // (constraints.hpp).
    for (std::uint32_t line = 0; line < n; ++line)
        for (std::uint32_t row = 0; row + 1 < m; ++row) add(is_layer1(line) ? t->warp1 : t->warp2, line, row, line, row + 1);
    for (std::uint32_t line = 0; line < weft_lines; ++line)
        for (std::uint32_t row = 0; row < m; ++row) add(t->weft, line, row, (line + 1) % n, row);
    for (std::uint32_t line = 0; line < weft_lines; ++line) {
        for (std::uint32_t row = 0; row + 1 < m; ++row) add(t->shear, line, row, (line + 1) % n, row + 1);
        for (std::uint32_t row = 0; row + 1 < m; ++row) add(t->shear, (line + 1) % n, row, line, row + 1);
    }
    for (std::uint32_t line = 0; line < n; ++line)
        for (std::uint32_t row = 0; row + 2 < m; ++row) add(t->bend, line, row, line, row + 2);
    const std::uint32_t bend_lines = closed ? n : (n >= 2 ? n - 2 : 0);
    if (n > 2)
        for (std::uint32_t line = 0; line < bend_lines; ++line)
            for (std::uint32_t row = 0; row < m; ++row) add(t->bend, line, row, (line + 2) % n, row);
    if (!degenerate.empty()) return fail(std::string(p) + ": " + degenerate);
    // Each phase in particle order (strips, see above). A warp spring's `a` stays the end
    // nearer the fitting zone.
    for (SpringPhase* phase : {&t->warp1, &t->warp2, &t->weft, &t->shear, &t->bend}) {
        std::vector<std::uint32_t> order(phase->size());
        for (std::uint32_t k = 0; k < order.size(); ++k) order[k] = k;
        std::sort(order.begin(), order.end(), [&](std::uint32_t i, std::uint32_t j) {
            return std::pair(phase->a[i], phase->b[i]) < std::pair(phase->a[j], phase->b[j]);
        });
        SpringPhase sorted;
        for (std::uint32_t k : order) sorted.add(phase->a[k], phase->b[k], phase->rest_m[k]);
        *phase = std::move(sorted);
    }

    t->rest_shape = pos;

    // Rest area per particle: a quarter of each grid quad around it (two triangles).
    t->area_m2 = VectorX::Zero(n * m);
    for (std::uint32_t line = 0; line < weft_lines; ++line)
        for (std::uint32_t row = 0; row + 1 < m; ++row) {
            const std::uint32_t l1 = (line + 1) % n;
            const Vec3 p00 = pos.col(gi(line, row)), p01 = pos.col(gi(line, row + 1));
            const Vec3 p10 = pos.col(gi(l1, row)), p11 = pos.col(gi(l1, row + 1));
            const Real quad = Real(0.5) * ((p11 - p00).cross(p01 - p10)).norm();
            for (std::uint32_t corner : {at(line, row), at(line, row + 1), at(l1, row), at(l1, row + 1)})
                t->area_m2[corner] += quad / 4;
        }

    // Weft placement of layer 2 (method §4.2).
    for (std::uint32_t line = 0; line < n; ++line) {
        if (is_layer1(line)) continue;
        const std::uint32_t left = line - line % stride;
        const std::uint32_t right = (left + stride) % n;
        for (std::uint32_t row = 0; row < m; ++row) {
            t->weft_particle.push_back(at(line, row));
            t->weft_left.push_back(at(left, row));
            t->weft_right.push_back(at(right, row));
            // Along the chord in proportion to the rest lengths, so that on the chord every
            // weft segment has the same strain however uneven the segments are.
            Real segments = 0, before = 0;
            for (std::uint32_t k = left; k != right; k = (k + 1) % n) {
                if (k == line) before = segments;
                segments += rest(k, row, (k + 1) % n, row);
            }
            t->weft_t.push_back(before / segments);
        }
    }
    // Render triangles, counter-clockwise seen from the side the normals point to.
    for (std::uint32_t line = 0; line < weft_lines; ++line)
        for (std::uint32_t row = 0; row + 1 < m; ++row) {
            const std::uint32_t p00 = at(line, row), p01 = at(line, row + 1);
            const std::uint32_t p10 = at((line + 1) % n, row), p11 = at((line + 1) % n, row + 1);
            t->triangles.insert(t->triangles.end(), {p00, p01, p10, p10, p01, p11});
        }
    return std::shared_ptr<const Fabric>(std::move(t));
}

std::vector<Entity> character_colliders(Registry& registry, Entity character) {
    std::vector<Entity> out;
    registry.view<EllipsoidCollider>().each([&](Entity e, EllipsoidCollider& c) {
        if (c.character == character) out.push_back(e);
    });
    std::sort(out.begin(), out.end(), [](Entity a, Entity b) { return a.index < b.index; });
    return out;
}

Result<Entity> attach_skirt(Registry& registry, Entity character, const TubeParams& params) {
    if (auto ok = validate(params, "skirt"); !ok) return std::unexpected(ok.error());
    return attach_tube(registry, character, "skirt", params);
}

Result<Entity> attach_dress(Registry& registry, Entity character, const TubeParams& params) {
    if (auto ok = validate(params, "dress"); !ok) return std::unexpected(ok.error());
    return attach_tube(registry, character, "dress", params);
}

Result<Entity> attach_grid_garment(Registry& registry, Entity character, const GridGarment& grid, std::string_view name) {
    const std::string p(name);
    if (!registry.valid(character)) return fail(p + ": the character entity is not alive");
    const auto cells = static_cast<std::size_t>(grid.warp_lines) * static_cast<std::size_t>(std::max(grid.particles_per_line, 0));
    if (grid.grid_positions.cols() != static_cast<Eigen::Index>(cells) || grid.pinned.size() != cells)
        return fail(p + ": the grid's positions and pins do not match its " + std::to_string(grid.warp_lines) + " x " +
                    std::to_string(grid.particles_per_line) + " particles");
    if (std::none_of(grid.pinned.begin(), grid.pinned.end(), [](std::uint8_t k) { return k != 0; }))
        return fail(p + ": no particle is held to the body");
    if (auto ok = validate(grid.config.material, p + ".material"); !ok) return std::unexpected(ok.error());
    const std::vector<Entity> colliders = character_colliders(registry, character);
    if (colliders.empty()) return fail(p + ": the character has no ellipsoid colliders");
    if (colliders.size() > 64) return fail(p + ": the character has " + std::to_string(colliders.size()) +
                                           " colliders; a garment handles at most 64");
    const auto* transform = registry.try_get<Transform>(character);
    const Affine3 to_world = transform ? transform->matrix() : Affine3::Identity();
    const Matrix3X world = to_world * grid.grid_positions;
    auto topology = build_grid_topology(grid.warp_lines, grid.particles_per_line, grid.weft_stride, grid.closed, world, name);
    if (!topology) return std::unexpected(topology.error());
    const GarmentConfig& c = grid.config;
    Garment g = make_instance(*topology, to_particle_order(**topology, world), c.material, c.model, c.integrator, c.collision, c.color);
    g.config = c;
    g.body.character = character;

    // Where it is held: the pins' centre. Held between the midpoint of the waist and the
    // armpits and the midpoint of the armpits and the shoulders (a strapless dress, a top),
    // the upper arms hang outside it, against its sides, as they do beside the built-in
    // dress; held higher (a cape on the shoulders), it lies over them.
    Vec3 held = Vec3::Zero();
    int held_count = 0;
    for (std::size_t k = 0; k < cells; ++k)
        if (grid.pinned[k]) held += world.col(static_cast<Eigen::Index>(k)), ++held_count;
    held /= Real(held_count);
    bool arms_outside = false;
    const auto* landmarks = registry.try_get<BodyLandmarks>(character);
    const auto* pose = registry.try_get<Skeleton>(character);
    if (landmarks && pose && transform && !pose->global.empty()) {
        const Real waist = landmark_world(landmarks->waist.center, *pose, *transform).y();
        const Real arms = landmark_world(landmarks->arms_meet_trunk, *pose, *transform).y();
        const Real shoulders = Real(0.5) * (landmark_world(landmarks->left_shoulder, *pose, *transform).y() +
                                            landmark_world(landmarks->right_shoulder, *pose, *transform).y());
        arms_outside = held.y() > Real(0.5) * (waist + arms) && held.y() < Real(0.5) * (arms + shoulders);
    }
    // Anchor: the torso's collider nearest the pins (the pelvis for a skirt, the chest for a
    // dress), else the nearest of any.
    Real nearest = std::numeric_limits<Real>::infinity();
    bool nearest_is_trunk = false;
    for (Entity e : colliders) {
        const auto& collider = registry.get<EllipsoidCollider>(e);
        if (arms_outside && collider.region == BodyRegion::upper_arm) continue;
        const bool trunk = collider.region == BodyRegion::pelvis || collider.region == BodyRegion::torso;
        const Real d = (make_ellipsoid_frame(collider.world).center - held).norm();
        if ((trunk && !nearest_is_trunk) || (trunk == nearest_is_trunk && d < nearest)) {
            nearest = d;
            nearest_is_trunk = trunk;
            g.body.anchor = static_cast<std::int32_t>(g.body.colliders.size());
        }
        g.body.colliders.push_back(e);
    }
    return finish(registry, std::move(g), grid.pinned, grid.pin_weights);
}

Result<Garment> make_rectangle(const RectangleParams& r, std::span<const Entity> colliders) {
    if (auto ok = validate(r); !ok) return std::unexpected(ok.error());
    if (colliders.size() > 64) return fail("rectangle: at most 64 colliders, got " + std::to_string(colliders.size()));
    const int n = r.warp_lines, m = r.particles_per_line;
    Matrix3X grid(3, n * m);
    for (int line = 0; line < n; ++line)
        for (int row = 0; row < m; ++row) {
            const Real across = r.width_m * Real(line) / Real(n - 1);
            const Real down = r.length_m * Real(row) / Real(m - 1);
            grid.col(line * m + row) = r.origin + Vec3(across, r.hanging ? -down : 0, r.hanging ? 0 : down);
        }
    auto topology = build_grid_topology(n, m, r.weft_stride, false, grid, "rectangle");
    if (!topology) return std::unexpected(topology.error());
    Garment g = make_instance(*topology, to_particle_order(**topology, grid), r.material, r.model, r.integrator, r.collision, r.color);
    g.body.colliders.assign(colliders.begin(), colliders.end());
    if (r.pin_top_row)
        for (int line = 0; line < n; ++line) {
            const std::uint32_t p = (*topology)->grid[static_cast<std::size_t>(line * m)];
            g.state.inv_mass[p] = 0;
            PinBinding pin;
            pin.particle = p;
            pin.kind = PinKind::world;
            pin.local = g.state.x.col(p);
            g.state.pins.push_back(pin);
        }
    g.body.rest_local = g.state.x;
    return g;
}

Result<Entity> attach_rectangle(Registry& registry, const RectangleParams& r, std::span<const Entity> colliders) {
    auto g = make_rectangle(r, colliders);
    if (!g) return std::unexpected(g.error());
    const Entity e = registry.create();
    registry.emplace<Garment>(e, std::move(*g));
    registry.emplace<GarmentSolver>(e);
    return e;
}

void reset_garment(Registry& registry, Entity garment) {
    Garment* g = registry.try_get<Garment>(garment);
    if (g == nullptr) return;
    GarmentSolver* solver = registry.try_get<GarmentSolver>(garment);
    if (solver == nullptr) solver = &registry.emplace<GarmentSolver>(garment);
    reset_garment_state(registry, *g, *solver);
}

}  // namespace drape
