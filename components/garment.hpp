// A garment, split the way cloth engines split it (Jolt's SoftBodySharedSettings / creation
// settings / motion properties, NvCloth's Fabric / Cloth):
//   Fabric          cooked topology and rest lengths, immutable, shared by every instance;
//   GarmentConfig   per-instance configuration: model, collision mode, material, colour;
//   GarmentBody     what the garment is worn by: the character, its colliders, the anchor;
//   GarmentState    particle positions, velocities, inverse masses and pins;
//   GarmentCounters what the cloth systems did (read by statistics).
// Solver caches and scratch (candidate lists, collider frames, stability bounds) are not
// here: they belong to the cloth module (systems/cloth/garment_solver.hpp). Change the model
// or the material through systems/cloth/garment_config.hpp, which invalidates what depends
// on them.
//
// Conventions (method §3.2)
// - The garment is an m x n particle grid: `warp_lines` lines of `particles_per_line`
//   particles; a line runs along the warp (down from the fitting zone), a row along the
//   weft. Every `weft_stride`-th warp line is layer 1 (integrated); the lines between are
//   layer 2 (placed from their layer-1 neighbours, method §4.2).
// - Particles are stored layer 1 first: columns [0, layer1_count) of `x` are the layer-1
//   particles, so the simplified model integrates one contiguous block. Within a layer, a
//   big garment's particles are stored by `line_bands` bands of neighbouring lines, so that
//   threads working on different bands write different memory
//   (systems/cloth/garment_parts.hpp).
// - Springs are flat parallel index arrays (`SpringPhase`). Warp springs are listed line by
//   line from the fitting zone outward: `a` is the end nearer the pins.
// - `inv_mass` is the same in both models (1 / (areal density x area), 0 = pinned). In the
//   simplified model a layer-1 particle carries the mass and drag of the weft particles
//   placed from it, by their weights.
// The render system reads only `state.x`, `fabric->triangles` and `config.color`.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "drape/engine/core/math.hpp"
#include "drape/engine/core/registry.hpp"

namespace drape {

/// Which mass-spring model integrates the garment (method §3.1).
enum class ClothModel : std::uint8_t {
    simplified,  ///< The paper's: stretch springs, warp layer integrated, weft placed (§3.2).
    classic,     ///< Provot's: stretch, shear and bend springs, every particle integrated.
};

/// Which scheme steps the garment through a substep (docs/cloth.md "Two integrators").
enum class ClothIntegrator : std::uint8_t {
    shipped,  ///< Eq. 2 without its spring term, the springs as compliant constraints, the limits
              ///< and contact repair (docs/cloth.md "Solver"): stable at any stiffness and step.
    paper,    ///< The paper's as written: eq. 2 with its spring forces, explicit (method §3.3-§3.4),
              ///< layer 2 placed from layer 1 (§3.2), Provot's limit after the step (§4.1), then
              ///< each particle out of the ellipsoids with its normal velocity removed (§5);
              ///< substeps from its stability bound.
};

/// How the shipped solver's rounds solve the warp springs (docs/cloth.md "Warp lines solved
/// directly").
enum class WarpSolve : std::uint8_t {
    rounds,  ///< Gauss-Seidel, spring by spring, as every other set; tethers at the lines' rest length.
    lines,   ///< Each warp line at once (a tridiagonal solve per line), tethers with the warp
             ///< limit's slack: a line hangs at the stretch its modulus gives.
};

/// How particles find the ellipsoids they touch (method §5).
enum class CollisionMode : std::uint8_t {
    candidate_lists,  ///< Per-particle candidate lists + last-collided first.
    brute_force,      ///< Every particle against every ellipsoid.
};

/// Springs of one kind as flat parallel arrays (one entry per spring).
struct SpringPhase {
    std::vector<std::uint32_t> a;   ///< First particle (for warp springs: nearer the pins).
    std::vector<std::uint32_t> b;   ///< Second particle.
    std::vector<Real> rest_m;       ///< Rest length, > 0.

    [[nodiscard]] std::size_t size() const noexcept { return a.size(); }
    void add(std::uint32_t i, std::uint32_t j, Real rest) { a.push_back(i); b.push_back(j); rest_m.push_back(rest); }
};

/// The cooked garment: topology and rest lengths, immutable, shared by every instance.
struct Fabric {
    std::uint32_t warp_lines = 0;           ///< n: lines along the warp.
    std::uint32_t particles_per_line = 0;   ///< m: particles on each warp line.
    std::uint32_t weft_stride = 1;          ///< Every weft_stride-th line is layer 1.
    bool closed = false;                    ///< The weft wraps around (skirt, dress).
    std::uint32_t layer1_count = 0;         ///< Particles [0, layer1_count) are layer 1.
    std::uint32_t line_bands = 1;           ///< Bands of neighbouring lines the particles are stored by (see `grid`).

    std::vector<std::uint32_t> grid;        ///< Particle index of (line, row): grid[line * m + row].
    std::vector<std::uint8_t> layer;        ///< 1 or 2 per particle.
    VectorX area_m2;                        ///< Per particle: the rest area it stands for (a quarter of each quad around it).
    Matrix3X rest_shape;                    ///< The cut: the positions the rest lengths and areas were measured on, grid order
                                            ///< (column line * m + row), in the world where the garment was built.
    std::vector<std::uint32_t> triangles;   ///< Render triangles over the particle grid.

    // Structural springs (method §3.2, §4.1), both models.
    SpringPhase warp1;       ///< Warp springs between layer-1 particles.
    SpringPhase warp2;       ///< Warp springs on layer-2 lines.
    SpringPhase weft;        ///< Weft (structural) springs between neighbouring lines.
    SpringPhase shear;       ///< Classic only: grid diagonals.
    SpringPhase bend;        ///< Classic only: every second particle, warp and weft.

    // Weft carriage (method §4.2), one entry per layer-2 particle.
    std::vector<std::uint32_t> weft_particle;  ///< The layer-2 particle.
    std::vector<std::uint32_t> weft_left;      ///< Its layer-1 neighbour before it along the weft.
    std::vector<std::uint32_t> weft_right;     ///< Its layer-1 neighbour after it.
    std::vector<Real> weft_t;                  ///< Its place on the chord from left to right, (0, 1): the rest length
                                               ///< of the weft segments before it over that of the whole chord.

    [[nodiscard]] std::size_t particle_count() const noexcept { return layer.size(); }
};

/// The cloth in physical units (method §3.3, §4.1). Moduli are those of the sheet: force per
/// unit width per unit strain. A spring of the grid gets k = modulus x (A_a + A_b) / (2 L^2)
/// with A the rest areas its two particles stand for and L its rest length, so a finer grid
/// or a layer-1 spring standing for several lines is the same cloth.
struct ClothMaterial {
    Real areal_density_kg_m2 = Real(0.17);  ///< Mass per area (cotton lawn / poplin: 0.1-0.2).
    Real stretch_N_m = Real(2000);          ///< Stretch modulus of warp and weft.
    Real shear_N_m = Real(100);             ///< Classic only: shear springs' modulus.
    Real bend_N_m = Real(10);               ///< Bend springs' modulus: classic; simplified with weft_bend.
    Real drag_N_s_m3 = Real(0.3);           ///< Air drag per area per speed (method §3.3 k = this x particle area).
    Real friction = Real(0.4);              ///< Coulomb coefficient of the cloth on the body.
    Real strain_limit = Real(0.10);         ///< Provot: max relative over-stretch (method §4.1).
    Real compression_limit = Real(0.25);    ///< Shortest a spring may be, over its rest length (0: none).
    /// The share of strain_limit within which the warp and weft limits hold a spring each
    /// substep, leaving the rest of the limit to what the last collision does after them
    /// (docs/cloth.md "Solver"). Lower, the warp limit acts on a garment at rest and dynamic
    /// follow-the-leader's velocity correction keeps it moving (at 0.2 of 10 % a still skirt
    /// kept 1 cm/s); at 1 the springs below Provot's limit are the compliant constraints' own.
    Real limit_share = Real(0.5);
    int iterations = 4;                     ///< Constraint rounds per substep.
    int weft_bend = 0;                      ///< Simplified model, 1: bend springs along its weft rows at bend_N_m (an extension).
    int line_iterations = 8;                ///< WarpSolve::lines: most Newton steps per line solve (round).
    Real line_tolerance = Real(0.001);      ///< WarpSolve::lines: a spring's residual strain that ends them.
    Real candidate_margin_m = Real(0.08);   ///< Candidate lists: reach beyond the surface (method §5).
    friend bool operator==(const ClothMaterial&, const ClothMaterial&) = default;
};

/// How much of the anchor's own motion the particles feel (method §3.3's inertial term):
/// 1 is physical; 0 carries the garment rigidly with the body part it hangs from, so a
/// game can tame a hard turn or a jerk.
struct InertiaScales {
    Real linear = 1;   ///< Of the anchor's linear acceleration.
    Real angular = 1;  ///< Of its rotation (centrifugal and Coriolis terms).
    /// > 0: the most linear acceleration of the anchor the particles feel (m/s^2); a step
    /// whose felt acceleration (linear x the anchor's) is larger is felt as the linear scale
    /// that brings it to this bound, the rest carried rigidly (an animation's root stopping
    /// dead from 8 m/s at a jump's top). 0: no bound.
    Real max_linear_m_s2 = 0;
    /// > 0: the fastest the particles feel the anchor accelerate downward, along gravity, over
    /// its last two fixed steps (m/s^2; free fall, 9.81, the default, is the most a body that
    /// only pushes on the ground can do; a clip keyed at 30 Hz moves every other step at 60):
    /// the downward part of a step's felt acceleration beyond it is carried rigidly, the rest
    /// of the motion felt as `linear` and `max_linear_m_s2` say (an animated jump's root
    /// rising at 8 m/s and stopping dead at its top is a body pulled down at 30 g). 0: no
    /// bound, eq. 2's whole -m a (the paper's scheme as written).
    Real max_fall_m_s2 = Real(9.81);
    friend bool operator==(const InertiaScales&, const InertiaScales&) = default;
};

/// Per-instance configuration. Read freely; change `model` and `material` through
/// systems/cloth/garment_config.hpp so that the solver's caches follow.
struct GarmentConfig {
    ClothModel model = ClothModel::simplified;
    ClothIntegrator integrator = ClothIntegrator::shipped;
    WarpSolve warp_solve = WarpSolve::rounds;  ///< The shipped integrator's only.
    CollisionMode collision = CollisionMode::candidate_lists;
    ClothMaterial material;
    InertiaScales inertia;
    /// > 0: every particle hung from a pin stays within this x the rest length of its line
    /// up to that pin of where it hangs in the rest shape, carried by the anchor (the max
    /// distance of Unity Cloth, NvCloth's motion constraints; docs/cloth.md). 0: none.
    Real max_distance_share = 0;
    /// With a max distance: true, each sphere's centre is the particle's rest place skinned by
    /// the skin of the trunk and legs nearest it (GarmentBody::rest_on_skin: a raised thigh
    /// carries it, as Unity Cloth's and Jolt's skinned constraints); false, the anchor carries
    /// the rest shape.
    bool max_distance_on_skin = false;
    Vec3 color = Vec3(0.75f, 0.12f, 0.18f);  ///< Linear RGB.
    friend bool operator==(const GarmentConfig&, const GarmentConfig&) = default;
};

/// What a pin follows.
enum class PinKind : std::uint8_t {
    world,     ///< Fixed in world space at `local` (flat test cloth).
    collider,  ///< Rigidly bound to an ellipsoid: `local` in its unit-sphere frame.
    skinned,   ///< Skinned like a skin vertex: `local` in bind model space, `bones`/`weights`
               ///< blended with Skeleton::skinning, then the character's Transform.
};

/// What one particle is pinned to (method §3.5). Only particles with inv_mass == 0 have one.
struct PinBinding {
    std::uint32_t particle = 0;
    PinKind kind = PinKind::world;
    std::int32_t collider = -1;             ///< PinKind::collider: index into GarmentBody::colliders.
    Vec3 local = Vec3::Zero();              ///< See PinKind.
    Vec4i bones = Vec4i::Zero();            ///< Skinned pin: up to 4 bone indices.
    Vec4 weights = Vec4::Zero();            ///< Skinned pin: weights, sum 1 (unused: weight 0).
};

/// What the garment is worn by.
struct GarmentBody {
    Entity character;                        ///< The character wearing it.
    std::vector<Entity> colliders;           ///< EllipsoidCollider entities the garment collides with (<= 64).
    std::int32_t anchor = -1;                ///< Collider whose rigid motion is "the body" of method §3.3 (-1: none).
    Matrix3X rest_local;                     ///< Rest shape in the anchor's frame (rotation + centre), for resets.
    /// GarmentConfig::max_distance_on_skin: one per particle, its rest place bound to the skin of
    /// the trunk and legs as a skinned pin is (PinKind::skinned); empty otherwise.
    std::vector<PinBinding> rest_on_skin;
};

/// Particle state in structure-of-arrays form.
struct GarmentState {
    Matrix3X x;                   ///< Particle positions, world, m.
    Matrix3X v;                   ///< Particle velocities, m/s.
    VectorX inv_mass;             ///< 1/kg; 0 = pinned.
    std::vector<PinBinding> pins; ///< One per pinned particle.
};

/// Per-garment counters. `frame_*` restart each fixed step; the rest accumulate.
struct GarmentCounters {
    std::uint64_t frame_collision_tests = 0;  ///< Unit-sphere tests this fixed step (all substeps).
    std::uint64_t frame_collisions = 0;       ///< Particle-ellipsoid contacts resolved this step.
    std::uint64_t frame_list_rebuild_tests = 0; ///< Candidate-list (broad phase) tests this step.
    Real max_penetration_m = 0;               ///< Deepest penetration found this step (before response).
    int substeps = 1;                         ///< Substeps of the last fixed step.
    int substeps_stability = 1;               ///< This garment's need from the stability bound (method §3.4).
    int substeps_motion = 1;                  ///< This garment's need from collider surface travel.
    std::uint64_t unresolved = 0;             ///< Particles left inside overlapping ellipsoids after the re-test cap.
    std::uint64_t collision_tests = 0;        ///< Totals since creation.
    std::uint64_t collisions = 0;
    std::uint64_t list_rebuilds = 0;
    std::uint64_t list_rebuild_tests = 0;
    std::uint64_t repair_rounds = 0;          ///< Contact repair rounds run (limits and collision after the last collision).
    std::uint64_t line_steps = 0;             ///< WarpSolve::lines: Newton steps of the line solves, summed over sets and bands.
    int frame_repair_rounds = 0;              ///< Contact repair rounds in the last fixed step (all substeps).
    std::uint64_t budget_hits = 0;            ///< Substeps whose contact repair stopped at its round budget with springs still over the limit.
    std::uint64_t non_finite_values = 0;      ///< Non-finite coordinates found (then the garment was reset).
    std::uint64_t resets = 0;                 ///< Resets (non-finite state, or reset_garment()).
    std::uint64_t steps = 0;                  ///< Fixed steps simulated.
};

struct Garment {
    std::shared_ptr<const Fabric> fabric;   ///< Shared, immutable.
    GarmentConfig config;
    GarmentBody body;
    GarmentState state;
    GarmentCounters counters;
};

}  // namespace drape
