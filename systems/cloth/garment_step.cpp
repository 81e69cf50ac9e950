// Per-garment stages of the cloth systems (method §3-§5); order in garment_step.hpp.
#include "drape/systems/cloth/garment_step.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <span>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/systems/cloth/body.hpp"
#include "drape/systems/cloth/collision.hpp"
#include "drape/systems/cloth/integrator.hpp"
#include "drape/systems/cloth/pins.hpp"
#include "drape/systems/cloth/constraints.hpp"
#include "drape/systems/cloth/weft.hpp"

namespace drape {

// Dynamic follow-the-leader's damping s_damping (Müller et al. 2012): the share of a
// follower's warp-limit move that its leader's velocity gives back.
constexpr Real leader_damping = Real(0.9);

// Contact repair (repair_pushes): its rounds come from the fixed step's budget
// (ClothSolverSettings::repair_rounds_per_frame), shared out evenly over the substeps left;
// pushed_weight is the share of its inverse mass a pushed particle keeps in them. For
// settling_s after the garment is built or reset each substep may take at least
// settling_repair_rounds: the garment starts from its rest shape round a body already in
// the clip's pose of the moment, a hem across a bent knee, and falls onto the body (Robot-
// Expressive's dress: 57 % after the first frame at 48 rounds, 10.0 % at 96; put on 0.375 s
// into its walk, 70.2 % in its seventh frame with the larger budget in the first step only,
// 10.0 % with it for 1/6 s). Later in a walk more rounds do not help (Female_Alternative's
// skirt: 107 % at 48, 407 % at 96).
constexpr int settling_repair_rounds = 192;
constexpr double settling_s = 1.0 / 6.0;
constexpr Real pushed_weight = Real(0.1);

// The weft limit's work in a row, for sharing the rows out between parts: a spring it
// corrects (a chain solve) counts as about this many springs it only checks.
constexpr std::uint64_t correction_cost = 8;

ClothSubstep make_substep(int index, int count, double fixed_dt_s) noexcept {
    return ClothSubstep{index, count, fixed_dt_s, fixed_dt_s / count};
}

void begin_garment_step(const Registry& registry, Garment& g, GarmentSolver& s, int substeps) {
    prepare_solver(g, s);
    GarmentCounters& c = g.counters;
    c.frame_collision_tests = c.frame_collisions = c.frame_list_rebuild_tests = 0;
    c.max_penetration_m = 0;
    c.frame_repair_rounds = 0;
    c.substeps = substeps;
    ++c.steps;
    update_pin_targets(registry, g, s, false);
}

namespace {

// The anchor's rigid motion over the substep (integrator.hpp); none without an anchor.
AnchorMotion anchor_motion(const Registry& registry, const Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    AnchorMotion m;
    const GarmentBody& body = g.body;
    if (body.anchor < 0 || static_cast<std::size_t>(body.anchor) >= body.colliders.size()) return m;
    const auto* c = registry.try_get<EllipsoidCollider>(body.colliders[static_cast<std::size_t>(body.anchor)]);
    if (c == nullptr) return m;
    const EllipsoidFrame f0 = interpolate_collider(*c, Real(sub.index) / Real(sub.count));
    const EllipsoidFrame f1 = interpolate_collider(*c, Real(sub.index + 1) / Real(sub.count));
    if (!f0.active || !f1.active) return m;
    m.r0 = f0.rotation;
    m.c0 = f0.center;
    m.r1 = f1.rotation;
    m.c1 = f1.center;
    m.velocity_m_s = f1.velocity_m_s;
    m.angular_velocity_rad_s = f1.angular_velocity_rad_s;
    m.acceleration_m_s2 = f1.acceleration_m_s2;
    m.step_s = static_cast<Real>(sub.h_s) * Real(sub.count);
    m.velocity_before_m_s = s.anchor_known ? s.anchor_velocity_before : m.velocity_m_s;
    m.velocity_earlier_m_s = s.anchor_known ? s.anchor_velocity_earlier : m.velocity_before_m_s;
    m.angular_velocity_before_rad_s = s.anchor_known ? s.anchor_angular_before : m.angular_velocity_rad_s;
    return m;
}

}  // namespace

void integrate_garment(const Registry& registry, Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    prepare_solver(g, s);
    GarmentState& state = g.state;
    for (SpringSet& set : s.springs) std::fill(set.lambda.begin(), set.lambda.end(), Real(0));
    const AnchorMotion motion = anchor_motion(registry, g, s, sub);
    const Vec3 gravity(0, -standard_gravity_m_s2, 0);
    const Real h = static_cast<Real>(sub.h_s);
    const bool carry = g.config.model == ClothModel::simplified;
    // The paper's integrator: eq. 2's spring term first, at the start of the substep
    // (integrator.hpp add_spring_impulses), on this thread (a spring's two ends may lie in
    // different bands).
    if (g.config.integrator == ClothIntegrator::paper)
        for (const std::size_t k : s.explicit_sets)
            add_spring_impulses(s.springs[k], state.x, s.paper_inv_mass, h, state.v);
    // Band by band (garment_parts.hpp).
    for_each_part(s.parts.count, [&](std::size_t k) {
        for (const ParticleRun& r : s.parts.runs[k]) {
            const Eigen::Index count = r.end - r.begin;
            s.x_start.middleCols(r.begin, count) = state.x.middleCols(r.begin, count);
            s.push.middleCols(r.begin, count).setZero();
            std::fill(s.contacts.begin() + r.begin, s.contacts.begin() + r.end, 0);
        }
        for (const ParticleRun& r : s.parts.integrated_runs[k])
            predict_particles(state.x, state.v, s.inv_mass, s.drag_N_s_m, r.begin, r.end, motion, g.config.inertia, gravity, h);
        // §4.2: layer 2 is carried by the layer 1 it hangs between (weft.hpp).
        if (carry) carry_weft(*g.fabric, s.parts.weft_entries[k], state.inv_mass, s.x_start, state.x);
    });
    // Then the layer-2 particles whose chord crosses a band edge, both ends now predicted.
    if (carry) carry_weft(*g.fabric, s.parts.edge_weft_entries, state.inv_mass, s.x_start, state.x);
    if (sub.index == 0) {
        if (!s.anchor_known) s.settled_s = 0;
        s.settling = s.settled_s < settling_s * (1 - 1e-9);  // the steps of the first settling_s, rounding aside
        s.settled_s += sub.fixed_dt_s;
    }
    if (sub.index == 0) s.anchor_velocity_earlier = motion.velocity_before_m_s;
    s.anchor_velocity_before = motion.velocity_m_s;
    s.anchor_angular_before = motion.angular_velocity_rad_s;
    s.anchor_known = true;
    apply_pins(g, s, sub.index, sub.count, static_cast<Real>(sub.fixed_dt_s));
}

int constraint_rounds(const Garment& g) noexcept { return std::max(1, g.config.material.iterations); }

bool collides_after(int round, int rounds) noexcept { return (rounds - 1 - round) % constraint_rounds_per_collision == 0; }

void prepare_collision(const Registry& registry, Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    prepare_solver(g, s);
    update_frames(registry, g.body, s.frames, Real(sub.index + 1) / Real(sub.count));
    s.ground_m = ground_height(registry);
    ++s.frames_serial;
}

void constrain_round(Garment& g, GarmentSolver& s, const ClothSubstep& sub, int round) {
    prepare_solver(g, s);
    if (g.config.integrator == ClothIntegrator::paper) return;  // its springs are forces (integrate_garment)
    Matrix3X& x = g.state.x;
    const Real h = static_cast<Real>(sub.h_s);
    const Real limit = g.config.material.strain_limit;
    const int rounds = constraint_rounds(g);
    const bool tethers = round + 1 == rounds;
    // The positions are held one row per coordinate (the strips run in vector lanes) from a
    // round to the next when no collision round comes between them; x is written only
    // before a collision round (and so after the last round).
    const bool in_rows = round > 0 && !collides_after(round - 1, rounds);
    const bool write_back = collides_after(round, rounds) || tethers;
    // The max distance's spheres round the rest shape as the anchor carries it at the end of
    // the substep (prepare_collision placed the colliders there).
    const Real max_distance = g.config.max_distance_share;
    const bool spheres = tethers && max_distance > 0 && g.body.rest_local.cols() == x.cols();
    // Or round the rest places as the skin carries them (max_distance_on_skin; pins.hpp).
    const bool on_skin = spheres && s.sphere_target.cols() == x.cols();
    const Affine3 anchor = spheres ? anchor_frame(s.frames, g.body.anchor) : Affine3::Identity();
    // The springs joining two bands first, on this thread (none in a garment of one band).
    for (SpringSet& set : s.springs) {
        if (in_rows)
            solve_edge_springs(set, s.x_rows, s.inv_mass, h, limit);
        else
            solve_edge_springs(set, x, s.inv_mass, h, limit);
    }
    // Then band by band: positions in, every set in order, in the last round the tethers,
    // positions out.
    for_each_part(s.parts.count, [&](std::size_t k) {
        if (!in_rows)
            for (const ParticleRun& r : s.parts.runs[k])
                s.x_rows.middleCols(r.begin, r.end - r.begin) = x.middleCols(r.begin, r.end - r.begin);
        for (SpringSet& set : s.springs) {
            if (set.next.empty())
                solve_springs(set, k, s.x_rows, s.inv_mass, h, limit);
            else
                s.line_steps[k] += static_cast<std::uint64_t>(solve_lines(
                    set, k, s.x_rows, s.inv_mass, h, g.config.material.line_iterations, g.config.material.line_tolerance));
        }
        if (tethers) solve_tethers(s.tethers[k], s.x_rows);
        if (spheres && on_skin)
            solve_max_distance(s.tethers[k], s.sphere_previous, s.sphere_target, Real(sub.index + 1) / Real(sub.count),
                               g.body.rest_local, anchor, max_distance, s.x_rows);
        else if (spheres)
            solve_max_distance(s.tethers[k], g.body.rest_local, anchor, max_distance, s.x_rows);
        if (write_back)
            for (const ParticleRun& r : s.parts.runs[k])
                x.middleCols(r.begin, r.end - r.begin) = s.x_rows.middleCols(r.begin, r.end - r.begin);
    });
    for (std::uint64_t& steps : s.line_steps) {
        g.counters.line_steps += steps;
        steps = 0;
    }
}

void collide_round(const Registry&, Garment& g, GarmentSolver& s, const ClothSubstep&, int) {
    prepare_solver(g, s);
    if (g.config.integrator == ClothIntegrator::paper) return;  // it collides once, after Provot (finish_collision)
    // The constraints moved the particles since the last round: the lists are brought up to
    // date for where they are now (only what moved far enough is refreshed, collision.hpp).
    const bool lists = g.config.collision == CollisionMode::candidate_lists;
    if (lists) prepare_candidate_lists(g, s);
    Matrix3X& x = g.state.x;
    for_each_part(s.parts.count, [&](std::size_t k) {
        PartCounters& c = s.part_counters[k] = PartCounters{};
        if (lists) update_candidate_part(g, s, k, c);
        for (const auto [first, end] : s.parts.runs[k]) {
            s.x_round.middleCols(first, end - first) = x.middleCols(first, end - first);
            collide_part(g, s, x, g.state.v, first, end, /*respond_velocity=*/false, c);
            collide_ground(x, g.state.inv_mass, s.ground_m, first, end);
            for (Eigen::Index p = first; p < end; ++p) s.contacts[static_cast<std::size_t>(p)] |= s.last_collided[static_cast<std::size_t>(p)];
            s.push.middleCols(first, end - first) += x.middleCols(first, end - first) - s.x_round.middleCols(first, end - first);
        }
    });
    for (const PartCounters& c : s.part_counters) add_part_counters(g, c);
}

namespace {

// The paper's constraints (method §4.1-§4.2): Provot's limit, `iterations` Gauss-Seidel
// passes over layer 1's springs (the classic model: every structural spring), and Provot's
// velocities following his corrections: an integrated particle moved by d gets d / h more.
// The simplified model's layer 2 is then placed again from layer 1 where it now is
// (weft.hpp), and Provot's passes go over the springs with layer-2 particles; a layer-2
// particle, which has no velocity of its own, moves with its neighbours: its move over the
// substep / h. Those passes move layer-1 ends too, but give them no velocity: their moves
// answer layer 2's placement, not layer 1's motion, and a placement's d / h grows without
// bound as h shrinks (docs/cloth.md "Two integrators": at 1e5-1e6 N/m, hundreds of
// substeps, it pumped energy into the skirt until it diverged).
void paper_constraints(Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    Matrix3X& x = g.state.x;
    const VectorX& w = g.state.inv_mass;
    const Real limit = g.config.material.strain_limit;
    const int passes = constraint_rounds(g);
    const Real inv_h = static_cast<Real>(1 / sub.h_s);
    s.x_round = x;  // after the prediction
    for (int pass = 0; pass < passes; ++pass)
        for (const std::size_t k : s.provot_first) (void)provot_pass(*s.springs[k].springs, w, limit, x);
    for (Eigen::Index p = 0; p < s.integrated; ++p)
        if (w[p] != 0) g.state.v.col(p) += (x.col(p) - s.x_round.col(p)) * inv_h;  // pins: their velocity is the skin's
    if (g.config.model != ClothModel::simplified) return;
    for (const std::uint32_t p : g.fabric->weft_particle)
        if (w[p] != 0) x.col(p) = s.x_start.col(p);
    for (std::size_t k = 0; k < s.parts.count; ++k) carry_weft(*g.fabric, s.parts.weft_entries[k], w, s.x_start, x);
    carry_weft(*g.fabric, s.parts.edge_weft_entries, w, s.x_start, x);
    for (int pass = 0; pass < passes; ++pass)
        for (const std::size_t k : s.provot_then) (void)provot_pass(*s.springs[k].springs, w, limit, x);
    for (Eigen::Index p = s.integrated; p < x.cols(); ++p)
        if (w[p] != 0) g.state.v.col(p) = (x.col(p) - s.x_start.col(p)) * inv_h;
}

}  // namespace

void finish_constraints(Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    prepare_solver(g, s);
    if (g.config.integrator == ClothIntegrator::paper) {
        paper_constraints(g, s, sub);
        return;
    }
    const Real stretch = g.config.material.limit_share * g.config.material.strain_limit;
    for_each_part(s.parts.count, [&](std::size_t k) {
        const auto [first_line, end_line] = s.parts.lines[k];
        s.part_counters[k].warp_moved =
            limit_warp_lines(*g.fabric, s.warp_rest_above, s.inv_mass, stretch, g.state.x, s.warp_moves, first_line, end_line);
    });
    // Then the weft, row by row: a row crosses every band, so the rows are shared out
    // instead, in runs of neighbouring rows of about the same work. A row's work is its
    // springs, checked in every pass, and the corrections it took in the last substep (most
    // near a dress's hem, where the legs stretch it); where the runs end does not change the
    // result, the rows being independent of each other.
    const std::size_t parts = s.parts.count;
    const std::uint32_t rows = g.fabric->particles_per_line;
    std::vector<std::uint32_t>& work = s.weft_row_work;
    work.resize(rows, 0);
    std::array<std::uint32_t, max_parts + 1> edge{};
    edge[parts] = rows;
    if (parts > 1) {
        const auto cost = [&](std::uint32_t row) { return std::uint64_t(g.fabric->warp_lines) + correction_cost * work[row]; };
        std::uint64_t total = 0;
        for (std::uint32_t row = 0; row < rows; ++row) total += cost(row);
        std::uint64_t sum = 0;
        std::size_t k = 1;
        for (std::uint32_t row = 0; row < rows && k < parts; ++row) {
            sum += cost(row);
            while (k < parts && sum * parts >= total * k) edge[k++] = row + 1;
        }
        for (; k < parts; ++k) edge[k] = rows;
    }
    for_each_part(parts, [&](std::size_t k) {
        std::uint64_t corrected = 0;
        for (std::uint32_t row = edge[k]; row < edge[k + 1]; ++row) {
            const std::uint64_t c = limit_weft_rows(*g.fabric, s.weft_rest_right, s.inv_mass, stretch, g.state.x, s.weft_moves, row,
                                                    row + 1, &s.part_scratch[k].weft);
            work[row] = static_cast<std::uint32_t>(c);
            corrected += c;
        }
        s.part_counters[k].weft_moved = corrected;
    });
}

std::uint64_t count_non_finite(const Garment& g) {
    return static_cast<std::uint64_t>((!g.state.x.array().isFinite()).count() + (!g.state.v.array().isFinite()).count());
}

namespace {

// The velocity after the substep of the free particles [first, end), layer 2 too: its move
// over the substep, as Provot's velocities follow his corrections, with two parts that are
// not motion:
// - the warp limit's move of the particle below it on its line (follow the leader with the
//   damping of dynamic follow-the-leader: the leader feels most of what it did to the
//   follower, which a one-sided move would otherwise add as energy);
// - where it touched an ellipsoid or the floor, the push-outs: across the surface it keeps the normal
//   velocity it had without them where that leaves the surface, else the surface's (no
//   approach, method §5); along it, the motion relative to the surface slowed by Coulomb
//   friction (shortened by `friction` x the approach removed, never reversed).
void update_velocities(Garment& g, GarmentSolver& s, const ClothSubstep& sub, Eigen::Index first, Eigen::Index end) {
    Matrix3X& x = g.state.x;
    Matrix3X& v = g.state.v;
    const Real inv_h = static_cast<Real>(1 / sub.h_s);
    const Real friction = g.config.material.friction;
    for (Eigen::Index p = first; p < end; ++p) {
        if (s.inv_mass[p] == 0) continue;  // pins: their velocity is the skin's
        Vec3 moved = (x.col(p) - s.x_start.col(p)) * inv_h;
        const std::uint32_t below = s.below[static_cast<std::size_t>(p)];
        if (below != static_cast<std::uint32_t>(p)) moved -= leader_damping * inv_h * s.warp_moves.col(below);
        const std::uint64_t touched = s.contacts[static_cast<std::size_t>(p)];
        const bool floor = on_ground(x.col(p), s.ground_m);
        if (touched == 0 && !floor) {
            v.col(p) = moved;
            continue;
        }
        const Vec3 unpushed = moved - s.push.col(p) * inv_h;
        Vec3 vp = moved;
        for (std::uint64_t bits = touched; bits != 0; bits &= bits - 1) {
            const EllipsoidFrame& f = s.frames[static_cast<std::size_t>(std::countr_zero(bits))];
            if (!f.active) continue;
            const Vec3 normal = (f.to_unit.transpose() * to_unit_sphere(f, x.col(p))).normalized();
            if (!normal.allFinite()) continue;
            const Vec3 surface = body_velocity_at(f, x.col(p));
            const Real away = (unpushed - surface).dot(normal);
            Vec3 tangential = (vp - surface) - (vp - surface).dot(normal) * normal;
            if (away < 0) {
                const Real t_len = tangential.norm();
                if (t_len > 0) tangential *= std::max(Real(0), 1 + friction * away / t_len);
            }
            vp = surface + tangential + std::max(away, Real(0)) * normal;
        }
        if (floor) {  // the floor: a surface at rest, its normal +Y
            const Real away = unpushed.y();
            Vec3 tangential(vp.x(), 0, vp.z());
            if (away < 0) {
                const Real t_len = tangential.norm();
                if (t_len > 0) tangential *= std::max(Real(0), 1 + friction * away / t_len);
            }
            vp = tangential + Vec3(0, std::max(away, Real(0)), 0);
        }
        v.col(p) = vp;
    }
}

// Whether part `part`'s candidate lists were brought up to date with the colliders where
// they are now (in this substep's rounds).
bool lists_up_to_date(const Garment& g, const GarmentSolver& s, std::size_t part) {
    const CandidateLists& lists = s.lists;
    return g.config.collision == CollisionMode::candidate_lists && lists.valid && part < lists.parts.size() &&
           lists.parts[part].valid && lists.parts[part].frames_serial == s.frames_serial;
}

// Particle p, moved since its list was last brought up to date, to be collided again:
// its list where the list still holds, else every collider, in s.repair_lists, and how
// far it may still move from where it is now in s.repair_slack_m. A list holds while its
// part's lists are up to date (lists_up_to_date) and the particle stays within its slack of
// where it was at the update (collision.hpp step 1). `anchor`: the lists' frame (rigid, so
// it keeps distances).
void hold_list(const Garment& g, GarmentSolver& s, const Affine3& anchor, std::uint32_t p) {
    Real left = -1;
    if (lists_up_to_date(g, s, s.parts.band[p])) {
        const Vec3 then(s.lists.scratch(0, p), s.lists.scratch(1, p), s.lists.scratch(2, p));
        left = s.lists.slack_m[p] - (anchor.linear().transpose() * (g.state.x.col(p) - anchor.translation()) - then).norm();
    }
    s.repair_lists[p] = left >= 0 ? s.lists.bits[p] : ~std::uint64_t(0);
    s.repair_slack_m[p] = std::max(left, Real(0));
}

// The warp and weft limits moved particles after the last collision round (on the sample
// scene's walk the warp limit 153 of 837 per substep, 61 of them by a millimetre or more):
// in band `part`, each block of 64 particles holding one is collided again, in the
// garment's collision mode (the band's lists brought up to date first), positions only; the
// last round's contacts are kept. The particles it pushes go to s.pushed[part].
void collide_limit_moves(Garment& g, GarmentSolver& s, std::size_t part, PartCounters& c) {
    std::vector<std::uint32_t>& pushed = s.pushed[part];
    pushed.clear();
    constexpr Eigen::Index block = 64;
    bool lists_current = false;
    std::array<std::uint64_t, block> before{};
    for (const auto [first, n] : s.parts.runs[part]) {
        for (Eigen::Index begin = first; begin < n; begin += block) {
            const Eigen::Index end = std::min(begin + block, n);
            if (s.warp_moves.middleCols(begin, end - begin).cwiseAbs().maxCoeff() == 0 &&
                s.weft_moves.middleCols(begin, end - begin).cwiseAbs().maxCoeff() == 0)
                continue;
            if (!lists_current && g.config.collision == CollisionMode::candidate_lists) {
                update_candidate_part(g, s, part, c);
                lists_current = true;
            }
            s.x_round.middleCols(begin, end - begin) = g.state.x.middleCols(begin, end - begin);
            std::copy(s.last_collided.begin() + begin, s.last_collided.begin() + end, before.begin());
            collide_part(g, s, g.state.x, g.state.v, begin, end, /*respond_velocity=*/false, c);
            for (Eigen::Index p = begin; p < end; ++p) {
                const std::size_t i = static_cast<std::size_t>(p);
                s.contacts[i] |= s.last_collided[i];
                s.last_collided[i] |= before[static_cast<std::size_t>(p - begin)];  // last round's contacts stay
                if (g.state.x.col(p) != s.x_round.col(p)) pushed.push_back(static_cast<std::uint32_t>(p));
            }
            s.push.middleCols(begin, end - begin) += g.state.x.middleCols(begin, end - begin) - s.x_round.middleCols(begin, end - begin);
        }
    }
}

// Which springs of free particle p are longer than (1 + limit) x rest: bit 0 a warp spring
// (to the particle above or below on its line), bit 1 a weft spring (to a neighbouring line).
int over_limit(const Fabric& f, const GarmentSolver& s, const Matrix3X& x, std::uint32_t p, Real limit) {
    const std::uint32_t m = f.particles_per_line, n = f.warp_lines;
    const std::uint32_t line = s.grid_line[p], row = s.grid_row[p];
    const Real scale = 1 + limit;
    const auto over = [&](std::uint32_t q, Real rest) { return (x.col(q) - x.col(p)).squaredNorm() > scale * scale * rest * rest; };
    int springs = 0;
    if ((row > 0 && over(s.above[p], s.warp_rest_above[p])) || (row + 1 < m && over(s.below[p], s.warp_rest_above[s.below[p]])))
        springs |= 1;
    if ((line > 0 || f.closed) && over(f.grid[((line + n - 1) % n) * m + row], s.weft_rest_right[f.grid[((line + n - 1) % n) * m + row]]))
        springs |= 2;
    else if ((line + 1 < n || f.closed) && over(f.grid[((line + 1) % n) * m + row], s.weft_rest_right[p]))
        springs |= 2;
    return springs;
}

// Part `part`'s particles in s.part_scratch[part].collide (moved after the lists were last
// brought up to date) collided again, positions only, one at a time (they are few and
// scattered: no blocks), each against its list where it still holds, else every active
// ellipsoid (hold_list): the same contacts either way, for fewer tests. The particles
// pushed go to s.pushed[part].
void collide_moved(Garment& g, GarmentSolver& s, std::size_t part) {
    PartScratch& ps = s.part_scratch[part];
    std::vector<std::uint32_t>& pushed = s.pushed[part];
    pushed.clear();
    if (ps.collide.empty()) return;  // (collide_particles takes an empty list as every particle)
    Matrix3X& x = g.state.x;
    const std::span<const std::uint32_t> moved = ps.collide;
    ps.touched.resize(moved.size());
    const bool lists = g.config.collision == CollisionMode::candidate_lists;
    const Affine3 anchor = anchor_frame(s.frames, g.body.anchor);
    for (std::size_t k = 0; k < moved.size(); ++k) {
        const std::uint32_t p = moved[k];
        s.x_round.col(p) = x.col(p);
        ps.touched[k] = s.last_collided[p];
        if (lists) hold_list(g, s, anchor, p);
    }
    const std::span<const Real> slack(s.repair_slack_m.data(), lists ? static_cast<std::size_t>(s.repair_slack_m.size()) : 0);
    const CollisionResult r = collide_particles(x, g.state.v, g.state.inv_mass, s.frames, lists ? &s.repair_lists : nullptr,
                                                s.last_collided, nullptr, g.config.material.friction, slack, 0, -1,
                                                /*respond_velocity=*/false, s.above, moved);
    PartCounters& c = s.part_counters[part];
    c.collision_tests += r.tests;
    c.collisions += r.collisions;
    c.max_penetration_m = std::max(c.max_penetration_m, r.max_penetration_m);
    for (std::size_t k = 0; k < moved.size(); ++k) {
        const std::uint32_t p = moved[k];
        s.contacts[p] |= s.last_collided[p];
        s.last_collided[p] |= ps.touched[k];  // the last round's contacts stay
        if (x.col(p) == s.x_round.col(p)) continue;
        s.push.col(p) += x.col(p) - s.x_round.col(p);
        pushed.push_back(p);
    }
}

// `list` sorted, each entry once.
template <class T>
void sort_unique(std::vector<T>& list) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
}

// `list` (values below `universe`) sorted, each entry once, as sort_unique gives it. A long
// list (a round's moved particles, thousands with repeats, or the rows they chose) is
// marked in `marks`, a bit per value, and read back in order, in time linear in its length
// and the universe's words; `marks` is all clear before and after.
void sort_unique_below(std::vector<std::uint32_t>& list, std::size_t universe, std::vector<std::uint64_t>& marks) {
    constexpr std::size_t short_list = 64;
    if (list.size() < short_list || std::any_of(list.begin(), list.end(), [&](std::uint32_t v) { return v >= universe; })) {
        sort_unique(list);
        return;
    }
    marks.resize((universe + 63) / 64);  // new words are clear
    for (const std::uint32_t v : list) marks[v >> 6] |= std::uint64_t(1) << (v & 63);
    list.clear();
    for (std::size_t w = 0; w < marks.size(); ++w) {
        for (std::uint64_t bits = marks[w]; bits != 0; bits &= bits - 1)
            list.push_back(static_cast<std::uint32_t>(w * 64 + static_cast<std::size_t>(std::countr_zero(bits))));
        marks[w] = 0;
    }
}

// The parts' lists in `out`, one after the other (the caller sorts them).
template <class T>
void gather(std::vector<T>& out, const std::vector<PartScratch>& parts, std::vector<T> PartScratch::*list) {
    out.clear();
    for (const PartScratch& p : parts) out.insert(out.end(), (p.*list).begin(), (p.*list).end());
}

// Whether the spring p-q of rest length `rest` is shorter than `shortest` x it, and its key
// in the repair's list of crushed springs (a << 32 | b, a < b).
bool is_crushed(const Matrix3X& x, std::uint32_t p, std::uint32_t q, Real rest, Real shortest) {
    return (x.col(q) - x.col(p)).squaredNorm() < shortest * shortest * rest * rest;
}
std::uint64_t spring_key(std::uint32_t p, std::uint32_t q) { return std::uint64_t(std::min(p, q)) << 32 | std::max(p, q); }

// The springs of free particle p shorter than `shortest` x their rest length, appended to
// `out` as a << 32 | b with a < b (contact repair's compression limit). Returns whether it
// found any.
bool find_crushed(const Fabric& f, const GarmentSolver& s, const Matrix3X& x, std::uint32_t p, Real shortest,
                  std::vector<std::uint64_t>& out) {
    if (!(shortest > 0)) return false;
    const std::uint32_t m = f.particles_per_line, n = f.warp_lines;
    const std::uint32_t line = s.grid_line[p], row = s.grid_row[p];
    bool found = false;
    const auto check = [&](std::uint32_t q, Real rest) {
        if (!is_crushed(x, p, q, rest, shortest)) return;
        out.push_back(spring_key(p, q));
        found = true;
    };
    if (row > 0) check(s.above[p], s.warp_rest_above[p]);
    if (row + 1 < m) check(s.below[p], s.warp_rest_above[s.below[p]]);
    if (n > 1 && (line > 0 || f.closed)) {
        const std::uint32_t q = f.grid[((line + n - 1) % n) * m + row];
        check(q, s.weft_rest_right[q]);
    }
    if (n > 1 && (line + 1 < n || f.closed)) check(f.grid[((line + 1) % n) * m + row], s.weft_rest_right[p]);
    return found;
}

// The springs shorter than `shortest` x their rest length with a free end whose first end
// lies on the lines [first, end), appended to `out` as find_crushed gives them (the caller
// sorts them). Every spring is looked at once, not only those of particles that moved: the
// limits' moves can crush a spring they do not stretch, and so can the rounds (a collision putting two neighbours on one point of a
// surface; in the classic model the shear and bend springs pressing a weft spring at the hem).
void find_crushed_lines(const Fabric& f, const GarmentSolver& s, const Matrix3X& x, std::pair<std::uint32_t, std::uint32_t> lines,
                        Real shortest, std::vector<std::uint64_t>& out) {
    if (!(shortest > 0)) return;
    const std::uint32_t m = f.particles_per_line, n = f.warp_lines;
    const VectorX& w = s.inv_mass;
    const Real* rest_above = s.warp_rest_above.data();
    const Real* rest_right = s.weft_rest_right.data();
    // Row by row, the way the particles are stored; a crushed spring is rare, so the test
    // runs without a branch and the few found are looked at after.
    for (std::uint32_t row = 0; row < m; ++row) {
        const bool down = row + 1 < m;
        for (std::uint32_t line = lines.first; line < lines.second; ++line) {
            const std::uint32_t p = f.grid[std::size_t(line) * m + row];
            const std::uint32_t q_down = f.grid[std::size_t(line) * m + (down ? row + 1 : row)];
            const bool right = n > 1 && (line + 1 < n || f.closed);
            const std::uint32_t q_right = f.grid[std::size_t(right ? (line + 1) % n : line) * m + row];
            const bool crushed_down = down & is_crushed(x, p, q_down, rest_above[q_down], shortest);
            const bool crushed_right = right & is_crushed(x, p, q_right, rest_right[p], shortest);
            if (!(crushed_down | crushed_right)) [[likely]]
                continue;
            if (crushed_down && (w[p] != 0 || w[q_down] != 0)) out.push_back(spring_key(p, q_down));
            if (crushed_right && (w[p] != 0 || w[q_right] != 0)) out.push_back(spring_key(p, q_right));
        }
    }
}

// The springs of s.repair_crushed pushed apart to `target` x their rest length, their ends
// sharing the move by the weights `w` (the point they weigh on stays), along their chord;
// where the ends meet, along the chord at the substep's start. The particles moved go to
// `moved`.
void push_apart(const Fabric& f, const GarmentSolver& s, Matrix3X& x, const VectorX& w, Real target,
                std::vector<std::uint32_t>& moved) {
    const std::uint32_t n = f.warp_lines;
    for (const std::uint64_t key : s.repair_crushed) {
        const auto a = static_cast<std::uint32_t>(key >> 32), b = static_cast<std::uint32_t>(key);
        const Real wsum = w[a] + w[b];
        if (!(wsum > 0)) continue;
        const std::uint32_t la = s.grid_line[a], lb = s.grid_line[b];
        Real rest = 0;
        if (la == lb)
            rest = s.warp_rest_above[s.grid_row[a] > s.grid_row[b] ? a : b];
        else
            rest = (la + 1) % n == lb ? s.weft_rest_right[a] : s.weft_rest_right[b];
        Vec3 d = x.col(b) - x.col(a);
        if (d.norm() < Real(1e-3) * rest) d = s.x_start.col(b) - s.x_start.col(a);
        if (d.norm() < Real(1e-3) * rest) d = Vec3::UnitY();
        d.normalize();
        const Vec3 centre = (w[b] * x.col(a) + w[a] * x.col(b)) / wsum;
        x.col(a) = centre - (w[a] / wsum) * target * rest * d;
        x.col(b) = centre + (w[b] / wsum) * target * rest * d;
        if (w[a] != 0) moved.push_back(a);
        if (w[b] != 0) moved.push_back(b);
    }
}

// Contact repair (an extension of method §4.1-§5, docs/cloth.md "Contact repair"): the last
// collision can push a particle far from neighbours the limits had just brought within
// reach (a heel lifting the hem, the back of a bent knee), and nothing after it restores the
// springs. Rounds of limit and collision: the lines and rows of every particle that moved
// (pushed, or moved by the last limits) and has a spring over the strain limit are
// limited again, a particle pushed in this substep taken as heavier (inverse mass x
// pushed_weight) so that the limits move its neighbours toward it rather than it back into
// the body; then what they moved is collided again. Until no spring of a moved particle is
// over the limit, or the substep's share of the fixed step's round budget (at least
// settling_repair_rounds while settling; the budget binding is counted in budget_hits).
// Each stage of a round runs in parts at the same time, on particles no other part touches:
// the check of the moved particles, the warp limit on a share of the listed lines, the weft
// limit on a share of the listed rows, the collision of what they moved by line (line number
// modulo the parts: a particle and the one above it on its line, toward which the
// collision's fallback may move it, in the same part, in index order). The result is the
// same bytes on any number of threads.
void repair_pushes(Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    const Fabric& f = *g.fabric;
    const std::uint32_t m = f.particles_per_line;
    const Real limit = g.config.material.strain_limit;
    const Real limit_share = g.config.material.limit_share;
    const Real stretch = limit_share * limit;
    // The compression limit as the strain limit: a spring shorter than it is chosen, and
    // pushed apart to within limit_share of it.
    const Real shortest = g.config.material.compression_limit;
    const Real apart = 1 - limit_share * (1 - shortest);
    const std::size_t parts = s.parts.count;
    Matrix3X& x = g.state.x;
    // Moved by the last limits: first, those the weft limit moved. The warp limit leaves no
    // warp spring over its bound and the weft limit then checks every weft spring, so a
    // spring over the limit after both has an end the weft limit moved (a row it did not
    // settle in its passes, or a warp spring its sideways move stretched).
    for_each_part(parts, [&](std::size_t k) {
        std::vector<std::uint32_t>& moved = s.part_scratch[k].collide;
        moved.clear();
        for (const auto [first, end] : s.parts.runs[k])
            for (Eigen::Index p = first; p < end; ++p)
                if (s.weft_moves.col(p).squaredNorm() > 0) moved.push_back(static_cast<std::uint32_t>(p));
    });
    s.repair_inv_mass = s.inv_mass;  // the pushed particles chosen are made heavier below
    const VectorX& w = s.repair_inv_mass;
    const int substeps_left = std::max(1, sub.count - sub.index);
    int rounds = (s.repair_rounds_left + substeps_left - 1) / substeps_left;
    if (s.settling) rounds = std::max(rounds, settling_repair_rounds);
    for (int round = 0;; ++round) {
        for_each_part(parts, [&](std::size_t k) {
            PartScratch& ps = s.part_scratch[k];
            ps.rows.clear();
            ps.lines.clear();
            ps.crushed.clear();
            const auto choose = [&](std::uint32_t p) {
                const int springs = over_limit(f, s, x, p, limit);
                if (springs & 1) ps.lines.push_back(s.grid_line[p]);
                if (springs & 2) ps.rows.push_back(s.grid_row[p]);
                const bool crushed = find_crushed(f, s, x, p, shortest, ps.crushed);
                return springs != 0 || crushed;
            };
            for (const std::uint32_t p : s.pushed[k])
                if (choose(p)) s.repair_inv_mass[p] = s.inv_mass[p] * pushed_weight;
            for (const std::uint32_t p : ps.collide) choose(p);
            if (round == 0) find_crushed_lines(f, s, x, s.parts.lines[k], shortest, ps.crushed);
        });
        gather(s.repair_rows, s.part_scratch, &PartScratch::rows);
        sort_unique_below(s.repair_rows, m, s.repair_marks);
        gather(s.repair_lines, s.part_scratch, &PartScratch::lines);
        sort_unique_below(s.repair_lines, f.warp_lines, s.repair_marks);
        gather(s.repair_crushed, s.part_scratch, &PartScratch::crushed);
        sort_unique(s.repair_crushed);
        if (s.repair_rows.empty() && s.repair_lines.empty() && s.repair_crushed.empty()) return;
        if (round == rounds) {  // the budget binds: springs are left over (or under) the limit
            ++g.counters.budget_hits;
            return;
        }
        ++g.counters.repair_rounds;
        ++g.counters.frame_repair_rounds;
        s.repair_rounds_left = std::max(0, s.repair_rounds_left - 1);
        // What the limits move is collided again and looked at in the next round; the moves
        // go back to zero.
        const auto take = [](Matrix3X& moves, std::uint32_t p, std::vector<std::uint32_t>& moved) {
            if (moves.col(p).squaredNorm() > 0) moved.push_back(p);
            moves.col(p).setZero();
        };
        const auto share = [&](const std::vector<std::uint32_t>& all, std::size_t k) {
            const std::size_t n = all.size();
            return std::span<const std::uint32_t>(all).subspan(n * k / parts, n * (k + 1) / parts - n * k / parts);
        };
        for_each_part(parts, [&](std::size_t k) {
            PartScratch& ps = s.part_scratch[k];
            ps.moved.clear();
            for (const std::uint32_t line : share(s.repair_lines, k)) {
                limit_warp_lines(f, s.warp_rest_above, w, stretch, x, s.repair_warp_moves, line, line + 1);
                for (std::uint32_t row = 0; row < m; ++row) {
                    const std::uint32_t p = f.grid[line * m + row];
                    s.warp_moves.col(p) += s.repair_warp_moves.col(p);  // given back to the leader's velocity
                    take(s.repair_warp_moves, p, ps.moved);
                }
            }
        });
        for_each_part(parts, [&](std::size_t k) {
            PartScratch& ps = s.part_scratch[k];
            const std::span<const std::uint32_t> rows = share(s.repair_rows, k);
            limit_weft_rows(f, s.weft_rest_right, w, stretch, x, s.repair_weft_moves, rows, &ps.weft);
            for (const std::uint32_t row : rows)
                for (std::uint32_t line = 0; line < f.warp_lines; ++line) take(s.repair_weft_moves, f.grid[line * m + row], ps.moved);
        });
        // The crushed springs (few), on this thread.
        push_apart(f, s, x, w, apart, s.part_scratch[0].moved);
        for_each_part(parts, [&](std::size_t k) {
            PartScratch& ps = s.part_scratch[k];
            ps.collide.clear();
            for (const PartScratch& other : s.part_scratch)
                for (const std::uint32_t p : other.moved)
                    if (s.repair_part[p] == k) ps.collide.push_back(p);
            sort_unique_below(ps.collide, static_cast<std::size_t>(x.cols()), ps.marks);
            collide_moved(g, s, k);
        });
    }
}

// Every value finite, in one vectorised pass: x * 0 is 0 for a finite x and NaN for an
// infinity or a NaN, and the sum carries the NaN (Eigen's allFinite() tests value by value).
template <class M>
bool all_finite(const M& m) {
    return !std::isnan((m.array() * 0).sum());
}

}  // namespace

namespace {

// The paper's collision (method §5), once per substep after Provot: every particle in the
// garment's collision mode out of the ellipsoids to where the line from the centre meets
// the surface, its velocity toward the surface (relative to its motion) removed, friction
// as the material gives it (the paper names none); the floor the same.
void paper_collision(Garment& g, GarmentSolver& s) {
    const bool lists = g.config.collision == CollisionMode::candidate_lists;
    if (lists) prepare_candidate_lists(g, s);
    Matrix3X& x = g.state.x;
    Matrix3X& v = g.state.v;
    for_each_part(s.parts.count, [&](std::size_t k) {
        PartCounters& c = s.part_counters[k] = PartCounters{};
        if (lists) update_candidate_part(g, s, k, c);
        for (const auto [first, end] : s.parts.runs[k]) {
            collide_part(g, s, x, v, first, end, /*respond_velocity=*/true, c);
            collide_ground(x, g.state.inv_mass, s.ground_m, first, end);
            for (Eigen::Index p = first; p < end; ++p)
                if (g.state.inv_mass[p] != 0 && on_ground(x.col(p), s.ground_m)) v(1, p) = std::max(v(1, p), Real(0));
            c.finite = c.finite && all_finite(x.middleCols(first, end - first)) && all_finite(v.middleCols(first, end - first));
        }
    });
}

// The shipped solver's end of a substep (finish_collision).
void shipped_collision(Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    // The lists are sized on this thread first when a limit moved anything.
    const bool moved = std::any_of(s.part_counters.begin(), s.part_counters.end(),
                                   [](const PartCounters& c) { return c.warp_moved > 0 || c.weft_moved > 0; });
    if (moved && g.config.collision == CollisionMode::candidate_lists) prepare_candidate_lists(g, s);
    for_each_part(s.parts.count, [&](std::size_t k) {
        PartCounters& c = s.part_counters[k] = PartCounters{};
        s.pushed[k].clear();
        if (moved) collide_limit_moves(g, s, k, c);
    });
    // Without a limit's move the repair still looks for crushed springs (the rounds' own).
    if (moved || g.config.material.compression_limit > 0) repair_pushes(g, s, sub);
    for_each_part(s.parts.count, [&](std::size_t k) {
        PartCounters& c = s.part_counters[k];
        for (const auto [first, end] : s.parts.runs[k]) {
            collide_ground(g.state.x, g.state.inv_mass, s.ground_m, first, end, &s.push);
            update_velocities(g, s, sub, first, end);
            c.finite = c.finite && all_finite(g.state.x.middleCols(first, end - first)) &&
                       all_finite(g.state.v.middleCols(first, end - first));
        }
    });
}

}  // namespace

void finish_collision(const Registry& registry, Garment& g, GarmentSolver& s, const ClothSubstep& sub) {
    prepare_solver(g, s);
    if (g.config.integrator == ClothIntegrator::paper)
        paper_collision(g, s);
    else
        shipped_collision(g, s, sub);
    bool finite = true;
    for (const PartCounters& c : s.part_counters) {
        add_part_counters(g, c);
        finite = finite && c.finite;
    }
    // A NaN or infinity must not spread: report it once, count it, and start again from rest.
    if (!finite) {
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
    const int rounds = constraint_rounds(g);
    for (int i = 0; i < substeps; ++i) {
        const ClothSubstep sub = make_substep(i, substeps, fixed_dt_s);
        integrate_garment(registry, g, s, sub);
        prepare_collision(registry, g, s, sub);
        for (int round = 0; round < rounds; ++round) {
            constrain_round(g, s, sub, round);
            if (!collides_after(round, rounds)) continue;
            if (hooks.collide_round)
                hooks.collide_round(g, s, sub);
            else
                collide_round(registry, g, s, sub, round);
        }
        finish_constraints(g, s, sub);
        if (hooks.after_constraints) hooks.after_constraints(g, s, sub);
        if (hooks.finish_collision)
            hooks.finish_collision(g, s, sub);
        else
            finish_collision(registry, g, s, sub);
    }
    return substeps;
}

void reset_garment_state(const Registry& registry, Garment& g, GarmentSolver& s) {
    prepare_solver(g, s);
    update_frames(registry, g.body, s.frames, 1);
    ++s.frames_serial;
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
    tuck_under_limbs(registry, g.body, s.frames, state.x, state.inv_mass);
    std::fill(s.last_collided.begin(), s.last_collided.end(), 0);
    s.lists.valid = false;
    s.anchor_known = false;
    collide_garment(g, s);
    s.ground_m = ground_height(registry);
    collide_ground(state.x, state.inv_mass, s.ground_m, 0, n);
    ++g.counters.resets;
}

}  // namespace drape
