// Per-garment stages of the cloth systems (method §3-§5); order in garment_step.hpp.
#include "systems/cloth/garment_step.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "components/ellipsoid_collider.hpp"
#include "systems/cloth/body.hpp"
#include "systems/cloth/collision.hpp"
#include "systems/cloth/integrator.hpp"
#include "systems/cloth/pins.hpp"
#include "systems/cloth/strain_limit.hpp"
#include "systems/cloth/weft.hpp"

namespace drape {

ClothSubstep make_substep(int index, int count, double fixed_dt_s) noexcept {
    return ClothSubstep{index, count, fixed_dt_s, fixed_dt_s / count};
}

void begin_garment_step(const Registry& registry, Garment& g, GarmentSolver& s, int substeps) {
    prepare_solver(g, s);
    GarmentCounters& c = g.counters;
    c.frame_collision_tests = c.frame_collisions = c.frame_list_rebuild_tests = 0;
    c.max_penetration_m = 0;
    c.substeps = substeps;
    ++c.steps;
    update_pin_targets(registry, g, s, false);
}

void integrate_garment(const Registry& registry, Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    prepare_solver(g, s);
    const Fabric& t = *g.fabric;
    GarmentState& state = g.state;
    const Real h = static_cast<Real>(sub.h_s);

    s.x_start = state.x;  // no allocation once sized
    // The body part carrying the garment at the start of the substep (method §3.3).
    BodyMotion body;
    const GarmentBody& worn = g.body;
    if (worn.anchor >= 0 && static_cast<std::size_t>(worn.anchor) < worn.colliders.size()) {
        if (const auto* c = registry.try_get<EllipsoidCollider>(worn.colliders[static_cast<std::size_t>(worn.anchor)])) {
            const EllipsoidFrame f = interpolate_collider(*c, Real(sub.index) / Real(sub.count));
            body = BodyMotion{f.center, f.velocity_m_s, f.acceleration_m_s2, f.angular_velocity_rad_s};
        }
    }
    const Vec3 gravity(0, -standard_gravity_m_s2, 0);
    const ClothMaterial& m = g.config.material;
    if (g.config.model == ClothModel::simplified) {
        const Eigen::Index count = static_cast<Eigen::Index>(t.layer1_count);
        const Real scale = t.layer1_mass_scale;
        s.force.leftCols(count).setZero();
        add_spring_forces(t.warp1, m.stretch_k_N_m * scale, state.x, s.force);
        add_spring_forces(t.weft1, m.stretch_k_N_m, state.x, s.force);
        integrate_particles(state.x, state.v, state.inv_mass, s.force, count, scale, m.drag_N_s_m, body, gravity, h);
    } else {
        s.force.setZero();
        add_spring_forces(t.warp1, m.stretch_k_N_m, state.x, s.force);
        add_spring_forces(t.warp2, m.stretch_k_N_m, state.x, s.force);
        add_spring_forces(t.weft, m.stretch_k_N_m, state.x, s.force);
        add_spring_forces(t.shear, m.shear_k_N_m, state.x, s.force);
        add_spring_forces(t.bend, m.bend_k_N_m, state.x, s.force);
        integrate_particles(state.x, state.v, state.inv_mass, s.force, state.x.cols(), 1, m.drag_N_s_m, body, gravity, h);
    }
    apply_pins(g, s, sub.index, sub.count, static_cast<Real>(sub.fixed_dt_s));
}

void constrain_garment(Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    prepare_solver(g, s);
    const Fabric& t = *g.fabric;
    Matrix3X& x = g.state.x;
    Matrix3X& v = g.state.v;
    StrainLimitOptions o;
    o.limit = g.config.material.strain_limit;
    o.iterations = g.config.material.strain_iterations;
    o.h_s = static_cast<Real>(sub.h_s);
    if (g.config.model == ClothModel::simplified) {
        // §4.1: layer 1, the weft springs between its lines symmetric only, then the warp
        // with its ordered pass last so that the 10 % bound holds exactly on the warp.
        StrainLimitOptions weft1 = o;
        weft1.ordered_pass = false;
        limit_strain(t.weft1, x, v, s.movable, weft1);
        limit_strain(t.warp1, x, v, s.movable, o);
        // §4.2: layer 2 placed in its planes from layer 1. Provot on the layer-2 springs
        // (item 3) is part of the placement: each particle's one free coordinate is kept where
        // its warp spring and weft segments hold the limit (weft.hpp), so after this no
        // layer-2 warp spring below a free particle exceeds 1.10 x rest either.
        // Under the fitting zone, chords out of reach of the pinned particle above them are
        // lifted first (weft.hpp); the layer-1 warp then gets its ordered pass again.
        if (lift_chords_below_pins(t, g.state.inv_mass, x, v, s.force, o.h_s, o.limit)) {
            StrainLimitOptions ordered = o;
            ordered.iterations = 0;
            limit_strain(t.warp1, x, v, s.movable, ordered);
        }
        compute_layer1_normals(t, x, s.normals);
        place_weft(t, s.normals, g.state.inv_mass, x, v, s.plane_normal, o.h_s, o.limit);
    } else {
        StrainLimitOptions weft = o;
        weft.ordered_pass = false;
        limit_strain(t.weft, x, v, s.movable, weft);
        limit_strain(t.warp1, x, v, s.movable, o);
        limit_strain(t.warp2, x, v, s.movable, o);
    }
}

void record_strain(Garment& g) {
    const Fabric& t = *g.fabric;
    const Matrix3X& x = g.state.x;
    g.counters.max_strain = std::max({max_strain(t.warp1, x), max_strain(t.warp2, x), max_strain(t.weft, x)});
}

std::uint64_t count_non_finite(const Garment& g) {
    return static_cast<std::uint64_t>((!g.state.x.array().isFinite()).count() + (!g.state.v.array().isFinite()).count());
}

namespace {
// Every value finite, in one vectorised pass: x * 0 is 0 for a finite x and NaN for an
// infinity or a NaN, and the sum carries the NaN (Eigen's allFinite() tests value by value).
bool all_finite(const Matrix3X& m) { return !std::isnan((m.array() * 0).sum()); }
}  // namespace

void collide_garment_step(const Registry& registry, Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    prepare_solver(g, s);
    update_frames(registry, g.body, s.frames, Real(sub.index + 1) / Real(sub.count));
    const CollisionResult r = collide_garment(g, s, nullptr, static_cast<Real>(sub.h_s));
    g.counters.unresolved += r.unresolved;

    // A NaN or infinity must not spread: report it once, count it, and start again from rest.
    if (!all_finite(g.state.x) || !all_finite(g.state.v)) {
        const std::uint64_t bad = count_non_finite(g);
        g.counters.non_finite_values += bad;
        std::fprintf(stderr, "drape: cloth: %llu non-finite particle values after step %llu; garment reset to rest\n",
                     static_cast<unsigned long long>(bad), static_cast<unsigned long long>(g.counters.steps));
        reset_garment_state(registry, g, s);
    }
}

int step_garment(const Registry& registry, Garment& g, GarmentSolver& s, double fixed_dt_s,
                 const ClothSolverSettings& settings, const StepHooks& hooks) {
    const int substeps = garment_substeps(registry, g, s, fixed_dt_s, settings);
    begin_garment_step(registry, g, s, substeps);
    for (int i = 0; i < substeps; ++i) {
        const ClothSubstep sub = make_substep(i, substeps, fixed_dt_s);
        integrate_garment(registry, g, s, sub);
        constrain_garment(g, s, sub);
        if (sub.last()) record_strain(g);
        if (hooks.after_constraints) hooks.after_constraints(g, s, sub);
        if (hooks.collide)
            hooks.collide(g, s, sub);
        else
            collide_garment_step(registry, g, s, sub);
        if (hooks.after_collision) hooks.after_collision(g, s, sub);
    }
    return substeps;
}

void reset_garment_state(const Registry& registry, Garment& g, GarmentSolver& s) {
    prepare_solver(g, s);
    update_frames(registry, g.body, s.frames, 1);
    const Affine3 anchor = anchor_frame(s.frames, g.body.anchor);
    GarmentState& state = g.state;
    const Eigen::Index n = state.x.cols();
    const std::int32_t a = g.body.anchor;
    const bool has_anchor = a >= 0 && static_cast<std::size_t>(a) < s.frames.size() && s.frames[static_cast<std::size_t>(a)].active;
    for (Eigen::Index p = 0; p < n; ++p) {
        state.x.col(p) = anchor * Vec3(g.body.rest_local.col(p));
        state.v.col(p) = has_anchor ? body_velocity_at(s.frames[static_cast<std::size_t>(a)], state.x.col(p)) : Vec3::Zero();
    }
    update_pin_targets(registry, g, s, true);
    for (std::size_t i = 0; i < state.pins.size(); ++i) {
        const std::uint32_t p = state.pins[i].particle;
        state.x.col(p) = s.pin_target.col(static_cast<Eigen::Index>(i));
    }
    std::fill(s.last_collided.begin(), s.last_collided.end(), 0);
    s.lists.valid = false;
    collide_garment(g, s);
    ++g.counters.resets;
}

}  // namespace drape
