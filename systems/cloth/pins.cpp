// Fitting-zone pins (method §3.5); conventions in pins.hpp.
#include "drape/systems/cloth/pins.hpp"

#include <string>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/systems/cloth/body.hpp"
#include "drape/systems/cloth/collision.hpp"
#include "drape/systems/cloth/garment_parts.hpp"

namespace drape {

Affine3 blend_skinning(const std::vector<Affine3>& skinning, const Vec4i& bones, const Vec4& weights) {
    Affine3 m;
    m.matrix().setZero();
    for (int i = 0; i < 4; ++i) {
        if (weights[i] == 0) continue;
        m.matrix() += weights[i] * skinning[static_cast<std::size_t>(bones[i])].matrix();
    }
    m.matrix().row(3) << 0, 0, 0, 1;
    return m;
}

Result<Vec3> evaluate_pin(const Registry& registry, const Garment& garment, const PinBinding& pin) {
    switch (pin.kind) {
        case PinKind::world: return pin.local;
        case PinKind::collider: {
            if (pin.collider < 0 || static_cast<std::size_t>(pin.collider) >= garment.body.colliders.size())
                return fail("pin " + std::to_string(pin.particle) + ": collider index out of range");
            const auto* c = registry.try_get<EllipsoidCollider>(garment.body.colliders[static_cast<std::size_t>(pin.collider)]);
            if (c == nullptr) return fail("pin " + std::to_string(pin.particle) + ": its collider is gone");
            return Vec3(c->world * pin.local);
        }
        case PinKind::skinned: {
            const auto* skeleton = registry.try_get<Skeleton>(garment.body.character);
            if (skeleton == nullptr) return fail("pin " + std::to_string(pin.particle) + ": the body has no skeleton");
            for (int i = 0; i < 4; ++i)
                if (pin.weights[i] != 0 &&
                    (pin.bones[i] < 0 || static_cast<std::size_t>(pin.bones[i]) >= skeleton->skinning.size()))
                    return fail("pin " + std::to_string(pin.particle) + ": bone " + std::to_string(pin.bones[i]) +
                                " has no skinning matrix");
            const Vec3 model = blend_skinning(skeleton->skinning, pin.bones, pin.weights) * pin.local;
            const auto* transform = registry.try_get<Transform>(garment.body.character);
            return transform ? Vec3(transform->matrix() * model) : model;
        }
    }
    return fail("pin: unknown kind");
}

namespace {

// GarmentConfig::max_distance_on_skin: each particle's rest place as the skin carries it now
// (a skinned pin's rule; pinned particles have no sphere and keep their rest place).
void update_sphere_targets(const Registry& registry, const Garment& g, GarmentSolver& s, bool snap) {
    const std::vector<PinBinding>& bound = g.body.rest_on_skin;
    const Eigen::Index n = g.state.x.cols();
    const auto* skeleton = registry.try_get<Skeleton>(g.body.character);
    if (!(g.config.max_distance_share > 0) || !g.config.max_distance_on_skin || static_cast<Eigen::Index>(bound.size()) != n ||
        skeleton == nullptr) {
        s.sphere_previous.resize(3, 0);
        s.sphere_target.resize(3, 0);
        return;
    }
    const bool first = s.sphere_target.cols() != n || s.sphere_previous.cols() != n;
    if (first) {
        s.sphere_previous = g.state.x;  // where a particle without a binding keeps its centre
        s.sphere_target.resize(3, n);
    } else {
        s.sphere_previous.swap(s.sphere_target);
    }
    // Each bone's skinning and the character's Transform in one map, once per step; a place is
    // then the weighted sum of its bones' images (linear blend skinning, as blend_skinning).
    const auto* transform = registry.try_get<Transform>(g.body.character);
    const Affine3 world = transform ? transform->matrix() : Affine3::Identity();
    const std::size_t bones = skeleton->skinning.size();
    std::vector<Affine3>& to_world = s.sphere_bones;
    to_world.resize(bones);
    for (std::size_t b = 0; b < bones; ++b) to_world[b] = world * skeleton->skinning[b];
    const std::size_t parts = s.parts.count;
    for_each_part(parts, [&](std::size_t k) {
        const Eigen::Index begin = n * static_cast<Eigen::Index>(k) / static_cast<Eigen::Index>(parts);
        const Eigen::Index end = n * static_cast<Eigen::Index>(k + 1) / static_cast<Eigen::Index>(parts);
        for (Eigen::Index p = begin; p < end; ++p) {
            const PinBinding& b = bound[static_cast<std::size_t>(p)];
            bool ok = b.kind == PinKind::skinned;
            for (int i = 0; i < 4 && ok; ++i) ok = b.weights[i] == 0 || (b.bones[i] >= 0 && static_cast<std::size_t>(b.bones[i]) < bones);
            if (!ok) {
                s.sphere_target.col(p) = s.sphere_previous.col(p);
                continue;
            }
            Vec3 at = Vec3::Zero();
            for (int i = 0; i < 4; ++i)
                if (b.weights[i] != 0) at += b.weights[i] * (to_world[static_cast<std::size_t>(b.bones[i])] * b.local);
            s.sphere_target.col(p) = at;
        }
    });
    if (first || snap) s.sphere_previous = s.sphere_target;
}

}  // namespace

void update_pin_targets(const Registry& registry, const Garment& g, GarmentSolver& s, bool snap) {
    update_sphere_targets(registry, g, s, snap);
    const std::vector<PinBinding>& pins = g.state.pins;
    const Eigen::Index n = static_cast<Eigen::Index>(pins.size());
    const bool first = s.pin_target.cols() != n;
    if (first) {
        s.pin_target.resize(3, n);
        for (Eigen::Index i = 0; i < n; ++i) s.pin_target.col(i) = g.state.x.col(pins[static_cast<std::size_t>(i)].particle);
    }
    s.pin_previous = s.pin_target;
    // Fitting-zone points sit on or outside the collision body (method §3.5): where an
    // ellipsoid stands out of the skin (a bone-bound ellipsoid does not blend like the skin
    // between two bones; an arm hangs against the chest) the pin leaves it the shortest way.
    update_frames(registry, g.body, s.pin_frames, 1);
    // Each pin on its own: a big garment's pins in as many ranges as it has parts.
    const std::size_t parts = s.parts.count;
    for_each_part(parts, [&](std::size_t k) {
        const Eigen::Index begin = n * static_cast<Eigen::Index>(k) / static_cast<Eigen::Index>(parts);
        const Eigen::Index end = n * static_cast<Eigen::Index>(k + 1) / static_cast<Eigen::Index>(parts);
        for (Eigen::Index i = begin; i < end; ++i) {
            Vec3 target = s.pin_target.col(i);
            if (auto p = evaluate_pin(registry, g, pins[static_cast<std::size_t>(i)])) target = *p;
            for (int pass = 0; pass < 16; ++pass) {  // overlapping ellipsoids (arm and chest) take a few
                bool moved = false;
                for (const EllipsoidFrame& f : s.pin_frames) {
                    if (!f.active) continue;
                    const Vec3 out = leave_ellipsoid(f, target);
                    moved = moved || out != target;
                    target = out;
                }
                if (!moved) break;
            }
            s.pin_target.col(i) = target;
        }
    });
    if (first || snap) s.pin_previous = s.pin_target;
}

void apply_pins(Garment& g, const GarmentSolver& s, int substep, int substeps, Real fixed_dt) {
    const Eigen::Index n = s.pin_target.cols();
    const bool last = substep + 1 >= substeps;
    const Real alpha = Real(substep + 1) / Real(substeps);
    for (Eigen::Index i = 0; i < n; ++i) {
        const std::uint32_t p = g.state.pins[static_cast<std::size_t>(i)].particle;
        g.state.x.col(p) = last ? Vec3(s.pin_target.col(i))
                                : Vec3((1 - alpha) * s.pin_previous.col(i) + alpha * s.pin_target.col(i));
        g.state.v.col(p) = (s.pin_target.col(i) - s.pin_previous.col(i)) / fixed_dt;
    }
}

}  // namespace drape
