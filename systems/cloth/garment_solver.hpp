// What the cloth module keeps for one garment between steps: collider frames, pin targets,
// candidate lists, stability bounds and scratch arrays. Private to the cloth module: users
// read the Garment component, never this. The cloth systems attach one to every garment
// entity (component GarmentSolver); code that steps a garment by hand keeps its own.
//
// Everything here is derived: a default-constructed GarmentSolver is valid and is filled on
// the next step. It follows the garment's configuration by itself (`built_for`): a changed
// model or material drops the caches that depend on them (systems/cloth/garment_config.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "drape/components/garment.hpp"
#include "drape/engine/core/math.hpp"
#include "drape/systems/cloth/constraints.hpp"
#include "drape/systems/cloth/garment_parts.hpp"

namespace drape {

/// One collider as the cloth sees it during a substep (unit sphere <-> world).
struct EllipsoidFrame {
    Mat3 to_unit = Mat3::Identity();   ///< diag(1/r) R^T.
    Mat3 rotation = Mat3::Identity();  ///< R.
    Vec3 center = Vec3::Zero();        ///< c, m.
    Vec3 radii_m = Vec3::Ones();
    Vec3 velocity_m_s = Vec3::Zero();
    Vec3 acceleration_m_s2 = Vec3::Zero();
    Vec3 angular_velocity_rad_s = Vec3::Zero();
    bool active = false;               ///< False when the collider entity is gone: never tested.
    Real give_m = 0;                   ///< EllipsoidCollider::give_m in world units (collision.hpp, "Give").
};

/// The candidate lists of one particle range (garment_parts.hpp): each range keeps its own
/// collider references, so that ranges are brought up to date independently.
struct CandidateListPart {
    bool valid = false;                      ///< False: rebuild before the next test.
    std::vector<Affine3> reference_frames;   ///< Per collider: its reference, unit sphere -> anchor frame when its bit was last refreshed in this range (zero: none).
    std::vector<Eigen::Index> spent;         ///< Scratch: the particles whose list is refreshed.
    VectorX room;                            ///< Scratch: a lower bound of each particle's room, per run.
    std::uint64_t frames_serial = 0;         ///< GarmentSolver::frames_serial when its lists were last brought up to date.
};

/// Candidate lists with their references (method §5, spatial locality; collision.hpp step 1).
struct CandidateLists {
    std::vector<std::uint64_t> bits;         ///< Per particle: bit e set = ellipsoid e is in its pre-collision list.
    bool valid = false;                      ///< False: rebuild every range before the next test.
    Matrix3XRows reference_x;                ///< Per particle: its reference point (anchor frame), where its whole list was last refreshed.
    std::vector<CandidateListPart> parts;    ///< Per particle range of GarmentSolver::parts.
    Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic> clearance_m; ///< Particle x collider: clearance of the particle's reference point from the collider's reference pose, +inf when listed or inactive, m.
    VectorX min_clearance_m;                 ///< Per particle: at most its least clearance over the colliders (a bound kept cheaply: lowered when a collider is refreshed, exact again when the particle's slack is), m.
    VectorX slack_m;                         ///< Per particle: how far it may still move before its list could miss a collider, after the last update (at most that), m.
    Matrix3XRows scratch;                    ///< Anchor-frame positions, reused every substep.
};

/// What one part's collision did in a stage, added to the garment's counters afterwards.
struct PartCounters {
    std::uint64_t collision_tests = 0, collisions = 0, list_tests = 0, list_rebuilds = 0;
    Real max_penetration_m = 0;
    std::uint64_t warp_moved = 0;  ///< Particles the warp limit moved.
    std::uint64_t weft_moved = 0;  ///< Springs the weft limit corrected.
    bool finite = true;
};

/// One part's scratch for the stages after the rounds (garment_step.cpp): its weft rows'
/// limit, and its share of contact repair's rounds.
struct PartScratch {
    WeftLimitScratch weft;
    std::vector<std::uint32_t> rows, lines;  ///< Repair: rows and lines its particles chose.
    std::vector<std::uint32_t> moved;        ///< Repair: particles its limits moved (in any part's lines).
    std::vector<std::uint32_t> collide;      ///< Repair: the moved particles of its lines, collided again.
    std::vector<std::uint64_t> crushed;      ///< Repair: springs under the compression limit its particles found (a << 32 | b, a < b).
    std::vector<std::uint64_t> touched;      ///< Per particle of `collide`: its last_collided before that collision.
    std::vector<std::uint64_t> marks;        ///< Repair: a bit per particle, all clear between uses (sort_unique_below).
};

struct GarmentSolver {
    GarmentConfig built_for;                 ///< The configuration the caches below were made for.
    const Fabric* built_fabric = nullptr;    ///< And the fabric.
    std::size_t built_pins = 0;              ///< And the number of pins.
    bool configured = false;                 ///< False until the first step (or after invalidate()).

    // Derived from the fabric, the pins and the configuration (prepare_solver).
    Eigen::Index integrated = 0;             ///< Particles [0, integrated) are integrated (simplified: layer 1).
    VectorX inv_mass;                        ///< Of every particle as the solver moves it: a layer-1 particle of the
                                             ///< simplified model carries the mass of the weft particles it carries.
    VectorX drag_N_s_m;                      ///< eq. 2's k per particle, with the same shares.
    GarmentParts parts;                      ///< The garment's work in fixed parts (garment_parts.hpp).
    std::vector<SpringSet> springs;          ///< The springs the model solves, in order.
    /// Simplified model with ClothMaterial::weft_bend: each particle to the second beside it
    /// on its weft row; `springs` points into it.
    std::shared_ptr<const SpringPhase> weft_bend;
    std::vector<Tethers> tethers;            ///< Long-range attachments from the pins, per line band.
    std::vector<std::uint32_t> below;        ///< Per particle: the particle below it on its line (itself in the last row).
    std::vector<std::uint32_t> above;        ///< Per particle: the particle above it on its line (itself in the first row).
    std::vector<std::uint32_t> grid_line;    ///< Per particle: its line (Fabric::grid's inverse, with grid_row).
    std::vector<std::uint32_t> grid_row;     ///< Per particle: its row.
    std::vector<std::uint32_t> repair_part;  ///< Per particle: the part whose repair collision takes it (its line modulo the parts).
    VectorX weft_rest_right;                 ///< Per particle: rest length of the weft spring to the next line.
    VectorX warp_rest_above;                 ///< Per particle: rest length of the warp spring to the particle above it
                                             ///< on its line (0 in the first row).
    Real drag_step_s = 0;                    ///< Largest stable step of the explicit drag.
    // The paper's integrator only (ClothIntegrator::paper).
    VectorX paper_inv_mass;                  ///< Per particle: a layer-1 particle of the simplified model with the mass
                                             ///< of the weft particles placed from it (they have none, method §3.2).
    std::vector<std::size_t> explicit_sets;  ///< Indices into `springs` whose forces are explicit (simplified: warp1).
    std::vector<std::size_t> provot_first, provot_then; ///< Sets Provot's limit passes over: before layer 2 is placed
                                             ///< from layer 1, and after (the simplified model's weft and layer-2 warp).
    Real spring_step_s = std::numeric_limits<Real>::infinity(); ///< Largest stable step of the explicit springs.

    std::vector<EllipsoidFrame> frames;      ///< Colliders at the current substep, one per GarmentBody::colliders.
    Real ground_m = -std::numeric_limits<Real>::infinity(); ///< The floor under the garment (collision.hpp ground_height).
    std::uint64_t frames_serial = 0;         ///< Counts the poses `frames` was given by the step (a new substep, a reset).
    std::vector<std::uint64_t> last_collided;///< Per particle: ellipsoids it was pushed out of last substep (temporal coherence).
    CandidateLists lists;

    Matrix3X pin_previous, pin_target;       ///< Pin positions at the start and end of the fixed step.
    /// GarmentConfig::max_distance_on_skin: the spheres' centres (GarmentBody::rest_on_skin
    /// skinned) at the start and end of the fixed step, one per particle; else empty.
    Matrix3X sphere_previous, sphere_target;
    std::vector<Affine3> sphere_bones;       ///< Scratch: each bone's skinning in world space, for the spheres.
    std::vector<EllipsoidFrame> pin_frames;  ///< Scratch: the colliders at the end of the fixed step, for the pins.
    Vec3 anchor_velocity_before = Vec3::Zero();      ///< The anchor's V when the velocities were last written.
    Vec3 anchor_velocity_earlier = Vec3::Zero();     ///< Its V one fixed step before that (the fall bound's two-step acceleration).
    Vec3 anchor_angular_before = Vec3::Zero();       ///< Its W then.
    bool anchor_known = false;               ///< False: no step yet (the anchor's motion so far counts as none).
    double settled_s = 0;                    ///< Simulated time since the build or the last reset.
    bool settling = false;                   ///< In the first 1/6 s after the build or a reset (contact repair's larger round budget).
    int repair_rounds_left = 384;            ///< Contact repair rounds left in this fixed step (set from ClothSolverSettings each step).

    // Scratch (no allocation per step once sized).
    Matrix3X x_start;                        ///< Positions at the start of the substep.
    Matrix3X x_round;                        ///< Positions before the current collision round.
    Matrix3XRows x_rows;                     ///< Positions one row per coordinate, for the constraint rounds.
    Matrix3X push;                           ///< Per particle: the collision rounds' push-outs this substep.
    std::vector<std::uint64_t> contacts;     ///< Per particle: ellipsoids it touched in this substep's rounds.
    Matrix3X warp_moves;                     ///< Per particle: the warp limit's move this substep.
    Matrix3X weft_moves;                     ///< Per particle: the weft limit's move this substep.
    Matrix3X repair_warp_moves;              ///< Per particle: the warp limit's move in the current repair round.
    Matrix3X repair_weft_moves;              ///< Per particle: the weft limit's move in the current repair round.
    VectorX repair_inv_mass;                 ///< The limits' inverse masses in the repair rounds (pushed particles heavier).
    std::vector<std::uint64_t> repair_lists; ///< Per particle collided in a repair round: its candidate list, or every collider.
    VectorX repair_slack_m;                  ///< Per particle collided in a repair round: how far its list still holds from where it is.
    std::vector<std::vector<std::uint32_t>> pushed; ///< Per part: particles the last collision after the limits pushed.
    std::vector<std::uint32_t> repair_rows, repair_lines; ///< The repair rounds' choices, all parts'.
    std::vector<std::uint64_t> repair_marks; ///< A bit per row or line, all clear between uses (sort_unique_below).
    std::vector<std::uint64_t> repair_crushed; ///< The repair rounds' springs under the compression limit, all parts'.
    std::vector<PartScratch> part_scratch;   ///< Per part.
    std::vector<std::uint32_t> weft_row_work; ///< Per weft row: springs the weft limit corrected in it last substep.
    std::vector<PartCounters> part_counters; ///< Per part: this stage's counts.
    std::vector<std::uint64_t> line_steps;   ///< Per part: Newton steps of its line solves in the current round.
};

/// Sizes the scratch arrays and masks for `garment` and drops the caches that depend on a
/// configuration other than the garment's (no-op when current).
void prepare_solver(const Garment& garment, GarmentSolver& solver);

/// Drops every cache (the next step rebuilds them).
void invalidate(GarmentSolver& solver);

}  // namespace drape
