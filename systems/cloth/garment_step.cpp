// Per-garment substep bodies of the cloth systems (method §3-§5); order in garment_step.hpp.
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
void prepare_garment(Garment& g) {
    const GarmentTopology& t = *g.topology;
    const Eigen::Index n = static_cast<Eigen::Index>(t.particle_count());
    if (g.force.cols() != n) g.force = Matrix3X::Zero(3, n);
    if (g.normals.cols() != static_cast<Eigen::Index>(t.layer1_count)) g.normals = Matrix3X::Zero(3, t.layer1_count);
    if (g.plane_normal.cols() != n) g.plane_normal = Matrix3X::Zero(3, n);
    if (g.movable.size() != static_cast<std::size_t>(n)) {
        g.movable.resize(static_cast<std::size_t>(n));
        g.movable_weft.resize(static_cast<std::size_t>(n));
        for (Eigen::Index i = 0; i < n; ++i) {
            const std::size_t k = static_cast<std::size_t>(i);
            g.movable[k] = g.inv_mass[i] != 0;
            g.movable_weft[k] = g.inv_mass[i] != 0 && t.layer[k] == 2;
        }
    }
    if (g.last_collided.size() != static_cast<std::size_t>(n)) g.last_collided.assign(static_cast<std::size_t>(n), 0);
}

void integrate_garment(const Registry& registry, Garment& g, const FrameContext& ctx) {
    prepare_garment(g);
    const GarmentTopology& t = *g.topology;
    const Real h = static_cast<Real>(ctx.h_s);
    if (ctx.substep == 0) {
        GarmentCounters& c = g.counters;
        c.frame_collision_tests = c.frame_collisions = c.frame_list_rebuild_tests = 0;
        c.max_penetration_m = 0;
        c.substeps = ctx.substeps;
        ++c.steps;
        update_pin_targets(registry, g, false);
    }

    g.x_start = g.x;  // no allocation once sized
    // The body part carrying the garment at the start of the substep (method §3.3).
    BodyMotion body;
    if (g.anchor >= 0 && static_cast<std::size_t>(g.anchor) < g.colliders.size()) {
        if (const auto* c = registry.try_get<EllipsoidCollider>(g.colliders[static_cast<std::size_t>(g.anchor)])) {
            const EllipsoidFrame f = interpolate_collider(*c, Real(ctx.substep) / Real(ctx.substeps));
            body = BodyMotion{f.center, f.velocity_m_s, f.acceleration_m_s2, f.angular_velocity_rad_s};
        }
    }
    const Vec3 gravity(0, -standard_gravity_m_s2, 0);
    const ClothMaterial& m = g.material;
    if (g.model == ClothModel::simplified) {
        const Eigen::Index count = static_cast<Eigen::Index>(t.layer1_count);
        const Real scale = t.layer1_mass_scale;
        g.force.leftCols(count).setZero();
        add_spring_forces(t.warp1, m.stretch_k_N_m * scale, g.x, g.force);
        add_spring_forces(t.weft1, m.stretch_k_N_m, g.x, g.force);
        integrate_particles(g.x, g.v, g.inv_mass, g.force, count, scale, m.drag_N_s_m, body, gravity, h);
    } else {
        g.force.setZero();
        add_spring_forces(t.warp1, m.stretch_k_N_m, g.x, g.force);
        add_spring_forces(t.warp2, m.stretch_k_N_m, g.x, g.force);
        add_spring_forces(t.weft, m.stretch_k_N_m, g.x, g.force);
        add_spring_forces(t.shear, m.shear_k_N_m, g.x, g.force);
        add_spring_forces(t.bend, m.bend_k_N_m, g.x, g.force);
        integrate_particles(g.x, g.v, g.inv_mass, g.force, g.x.cols(), 1, m.drag_N_s_m, body, gravity, h);
    }
    apply_pins(g, ctx.substep, ctx.substeps, static_cast<Real>(ctx.fixed_dt_s));
}

void constrain_garment(Garment& g, const FrameContext& ctx) {
    prepare_garment(g);
    const GarmentTopology& t = *g.topology;
    StrainLimitOptions o;
    o.limit = g.material.strain_limit;
    o.iterations = g.material.strain_iterations;
    o.h_s = static_cast<Real>(ctx.h_s);
    if (g.model == ClothModel::simplified) {
        // §4.1: layer 1, the weft springs between its lines symmetric only, then the warp
        // with its ordered pass last so that the 10 % bound holds exactly on the warp.
        StrainLimitOptions weft1 = o;
        weft1.ordered_pass = false;
        limit_strain(t.weft1, g.x, g.v, g.movable, weft1);
        limit_strain(t.warp1, g.x, g.v, g.movable, o);
        // §4.2: layer 2 placed in its planes from layer 1. Provot on the layer-2 springs
        // (item 3) is part of the placement: each particle's one free coordinate is kept where
        // its warp spring and weft segments hold the limit (weft.hpp), so after this no
        // layer-2 warp spring below a free particle exceeds 1.10 x rest either.
        // Under the fitting zone, chords out of reach of the pinned particle above them are
        // lifted first (weft.hpp); the layer-1 warp then gets its ordered pass again.
        if (lift_chords_below_pins(t, g.inv_mass, g.x, g.v, g.force, o.h_s, o.limit)) {
            StrainLimitOptions ordered = o;
            ordered.iterations = 0;
            limit_strain(t.warp1, g.x, g.v, g.movable, ordered);
        }
        compute_layer1_normals(t, g.x, g.normals);
        place_weft(t, g.normals, g.inv_mass, g.x, g.v, g.plane_normal, o.h_s, o.limit);
    } else {
        StrainLimitOptions weft = o;
        weft.ordered_pass = false;
        limit_strain(t.weft, g.x, g.v, g.movable, weft);
        limit_strain(t.warp1, g.x, g.v, g.movable, o);
        limit_strain(t.warp2, g.x, g.v, g.movable, o);
    }
    if (ctx.substep + 1 >= ctx.substeps)
        g.counters.max_strain = std::max({max_strain(t.warp1, g.x), max_strain(t.warp2, g.x), max_strain(t.weft, g.x)});
}

std::uint64_t count_non_finite(const Garment& g) {
    return static_cast<std::uint64_t>((!g.x.array().isFinite()).count() + (!g.v.array().isFinite()).count());
}

namespace {
// Every value finite, in one vectorised pass: x * 0 is 0 for a finite x and NaN for an
// infinity or a NaN, and the sum carries the NaN (Eigen's allFinite() tests value by value).
bool all_finite(const Matrix3X& m) { return !std::isnan((m.array() * 0).sum()); }
}  // namespace

void collide_garment_step(const Registry& registry, Garment& g, const FrameContext& context) {
    prepare_garment(g);
    update_frames(registry, g, Real(context.substep + 1) / Real(context.substeps));
    const CollisionResult r = collide_garment(g, nullptr, static_cast<Real>(context.h_s));
    g.counters.unresolved += r.unresolved;

    // A NaN or infinity must not spread: report it once, count it, and start again from rest.
    if (!all_finite(g.x) || !all_finite(g.v)) {
        const std::uint64_t bad = count_non_finite(g);
        g.counters.non_finite_values += bad;
        std::fprintf(stderr, "drape: cloth: %llu non-finite particle values after step %llu; garment reset to rest\n",
                     static_cast<unsigned long long>(bad), static_cast<unsigned long long>(g.counters.steps));
        reset_garment_state(registry, g);
    }
}

void reset_garment_state(const Registry& registry, Garment& g) {
    prepare_garment(g);
    update_frames(registry, g, 1);
    const Affine3 anchor = anchor_frame(g);
    const Eigen::Index n = g.x.cols();
    const bool has_anchor = g.anchor >= 0 && static_cast<std::size_t>(g.anchor) < g.frames.size() &&
                            g.frames[static_cast<std::size_t>(g.anchor)].active;
    for (Eigen::Index p = 0; p < n; ++p) {
        g.x.col(p) = anchor * Vec3(g.rest_local.col(p));
        g.v.col(p) = has_anchor ? body_velocity_at(g.frames[static_cast<std::size_t>(g.anchor)], g.x.col(p)) : Vec3::Zero();
    }
    update_pin_targets(registry, g, true);
    for (std::size_t i = 0; i < g.pins.size(); ++i) {
        const std::uint32_t p = g.pins[i].particle;
        g.x.col(p) = g.pin_target.col(static_cast<Eigen::Index>(i));
    }
    std::fill(g.last_collided.begin(), g.last_collided.end(), 0);
    g.lists_valid = false;
    collide_garment(g);
    ++g.counters.resets;
}

}  // namespace drape
