// An analytic walking body for cloth tests: 15 ellipsoids (pelvis, abdomen, chest, neck, head,
// upper arms, forearms, thighs, shins, feet) on a character entity without a skeleton,
// posed by closed-form joint angles. Each fixed step it writes the colliders' world,
// previous_world, velocity, acceleration and angular velocity as the collider system does.
#pragma once

#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"
#include "drape/systems/cloth/garment_step.hpp"
#include "drape/systems/cloth_systems.hpp"

namespace drape::test {

struct WalkSettings {
    double period_s = 1.1;        ///< One walk cycle (two steps).
    double hip_swing_rad = 0.45;  ///< Thigh swing amplitude.
    double knee_bend_rad = 0.7;
    double forward_speed_m_s = 1.2;
    double yaw_rad = 0.08;        ///< Pelvis yaw amplitude.
    double phase_s = 0;           ///< Time offset (different avatars, different phases).
    double spin_rad_s = 0;        ///< The whole body turning about the vertical (a spin in place).
    Vec3 origin = Vec3::Zero();
};

class AnalyticBody {
public:
    explicit AnalyticBody(Registry& registry, WalkSettings walk = {}) : m_walk(walk) {
        character = registry.create();
        for (int i = 0; i < 15; ++i) {
            const Entity e = registry.create();
            EllipsoidCollider c;
            c.character = character;
            c.bone = -1;
            registry.emplace<EllipsoidCollider>(e, c);
            colliders.push_back(e);
        }
        place(registry, 0, /*first=*/true);
    }

    /// Poses the body at time t (seconds) and updates the collider motion over `dt`.
    void place(Registry& registry, double t, bool first = false, double dt = 1.0 / 60.0) {
        const std::vector<Affine3> pose = poses(t + m_walk.phase_s);
        for (std::size_t i = 0; i < colliders.size(); ++i) {
            auto& c = registry.get<EllipsoidCollider>(colliders[i]);
            const Vec3 old_c = c.world.translation();
            const Vec3 old_v = c.velocity_m_s;
            c.previous_world = first ? pose[i] : c.world;
            c.world = pose[i];
            if (!first) {
                c.velocity_m_s = (c.world.translation() - old_c) / Real(dt);
                c.acceleration_m_s2 = c.initialised ? Vec3((c.velocity_m_s - old_v) / Real(dt)) : Vec3::Zero();
                const Mat3 r0 = rotation_of(c.previous_world), r1 = rotation_of(c.world);
                Quat q(Mat3(r1 * r0.transpose()));
                if (q.w() < 0) q.coeffs() = -q.coeffs();
                const Real s = q.vec().norm();  // (AngleAxis would use stableNorm, which GCC 12 warns about with AVX-512)
                const Real angle = 2 * std::atan2(s, q.w());
                c.angular_velocity_rad_s = s > 0 ? Vec3(q.vec() / s * (angle / Real(dt))) : Vec3::Zero();
            }
            c.initialised = true;
        }
    }

    /// A system that poses the body once per fixed step (phase skinning, like colliders).
    System system(Registry&) {
        return System{"analytic_body", Phase::skinning, {}, components<EllipsoidCollider>(), {},
                      [this](Registry& r, const FrameContext& ctx) {
                          place(r, ctx.time_s + ctx.fixed_dt_s, false, ctx.fixed_dt_s);
                      }};
    }

    Entity character;
    std::vector<Entity> colliders;

private:
    static Mat3 rotation_of(const Affine3& t) {
        Mat3 r = t.linear();
        for (int i = 0; i < 3; ++i) r.col(i).normalize();
        return r;
    }
    static Affine3 ellipsoid(const Vec3& centre, const Mat3& rotation, const Vec3& radii) {
        Affine3 a = Affine3::Identity();
        a.linear() = rotation * radii.asDiagonal();
        a.translation() = centre;
        return a;
    }

    std::vector<Affine3> poses(double t) const {
        const double w = 2 * std::numbers::pi / m_walk.period_s;
        const Real yaw = Real(m_walk.yaw_rad * std::sin(w * t) + m_walk.spin_rad_s * t);
        const Real bob = Real(0.02 * std::cos(2 * w * t));
        const Mat3 body_rot = Eigen::AngleAxis<Real>(yaw, Vec3::UnitY()).toRotationMatrix();
        const Vec3 root = m_walk.origin + Vec3(0, bob, Real(m_walk.forward_speed_m_s * t));
        auto B = [&](const Vec3& p) -> Vec3 { return root + body_rot * p; };
        std::vector<Affine3> out;
        out.push_back(ellipsoid(B({0, 0.95f, 0}), body_rot, {0.17f, 0.12f, 0.12f}));   // pelvis
        out.push_back(ellipsoid(B({0, 1.15f, 0}), body_rot, {0.15f, 0.14f, 0.11f}));   // abdomen
        out.push_back(ellipsoid(B({0, 1.36f, 0}), body_rot, {0.17f, 0.13f, 0.11f}));   // chest
        out.push_back(ellipsoid(B({0, 1.5f, 0}), body_rot, {0.06f, 0.07f, 0.06f}));    // neck
        out.push_back(ellipsoid(B({0, 1.66f, 0}), body_rot, {0.09f, 0.12f, 0.1f}));    // head
        for (int side = -1; side <= 1; side += 2) {
            const Real s = Real(side);
            const Real swing = Real(s * m_walk.hip_swing_rad * std::sin(w * t));
            const Real arm = -0.6f * swing;
            const Mat3 arm_rot = body_rot * Eigen::AngleAxis<Real>(arm, Vec3::UnitX()).toRotationMatrix();
            const Vec3 shoulder = B({s * 0.22f, 1.42f, 0});
            out.push_back(ellipsoid(shoulder + arm_rot * Vec3(0, -0.15f, 0), arm_rot, {0.05f, 0.15f, 0.05f}));
            const Vec3 elbow = shoulder + arm_rot * Vec3(0, -0.3f, 0);
            out.push_back(ellipsoid(elbow + arm_rot * Vec3(0, -0.14f, 0), arm_rot, {0.045f, 0.14f, 0.045f}));
            const Mat3 thigh_rot = body_rot * Eigen::AngleAxis<Real>(-swing, Vec3::UnitX()).toRotationMatrix();
            const Vec3 hip = B({s * 0.09f, 0.92f, 0});
            out.push_back(ellipsoid(hip + thigh_rot * Vec3(0, -0.22f, 0), thigh_rot, {0.075f, 0.23f, 0.075f}));
            const Real knee = Real(m_walk.knee_bend_rad * std::max(0.0, std::sin(w * t * s + 0.5)));
            const Mat3 shin_rot = thigh_rot * Eigen::AngleAxis<Real>(knee, Vec3::UnitX()).toRotationMatrix();
            const Vec3 knee_at = hip + thigh_rot * Vec3(0, -0.45f, 0);
            out.push_back(ellipsoid(knee_at + shin_rot * Vec3(0, -0.21f, 0), shin_rot, {0.055f, 0.22f, 0.055f}));
            const Vec3 ankle = knee_at + shin_rot * Vec3(0, -0.43f, 0);
            out.push_back(ellipsoid(ankle + shin_rot * Vec3(0, -0.03f, 0.05f), shin_rot, {0.05f, 0.04f, 0.12f}));
        }
        return out;
    }

    WalkSettings m_walk;
};

}  // namespace drape::test

namespace drape::test {

/// A registry with a walking analytic body, a scheduler running it and the cloth systems.
struct WalkingScene {
    explicit WalkingScene(WalkSettings walk = {}) : body(registry, walk) {
        scheduler.add(body.system(registry));
        add_cloth_systems(scheduler);
    }
    /// Runs `frames` frames of 1/60 s.
    void run(int frames) {
        for (int i = 0; i < frames; ++i) (void)scheduler.tick(registry, 1.0 / 60.0);
    }
    Registry registry;
    AnalyticBody body;
    Scheduler scheduler;
};

/// What a test runs between the systems: the garment, its solver, the substep and the frame.
using StageCheck = std::function<void(Garment&, GarmentSolver&, const ClothSubstep&, int frame)>;

// Steps garment `g` on `body` by hand for `frames` fixed 1/60 s steps through step_garment
// (the cloth systems' order and substeps), the body posed before each step.
// `after_constraints` runs after the constraint system has finished every substep;
// `collide_round`, when given, replaces each round of the collision system. `hold_pose`: the
// body keeps its pose of t = 0 instead of walking.
inline void step_by_hand(AnalyticBody& body, Registry& registry, Garment& g, GarmentSolver& solver, int frames,
                         const StageCheck& after_constraints = {}, const StageCheck& collide_round = {},
                         bool hold_pose = false) {
    const double dt = 1.0 / 60.0;
    for (int frame = 0; frame < frames; ++frame) {
        body.place(registry, hold_pose ? 0.0 : (frame + 1) * dt, false, dt);
        StepHooks hooks;
        if (after_constraints)
            hooks.after_constraints = [&](Garment& garment, GarmentSolver& s, const ClothSubstep& sub) {
                after_constraints(garment, s, sub, frame);
            };
        if (collide_round)
            hooks.collide_round = [&](Garment& garment, GarmentSolver& s, const ClothSubstep& sub) {
                collide_round(garment, s, sub, frame);
            };
        step_garment(registry, g, solver, dt, ClothSolverSettings{}, hooks);
    }
}

}  // namespace drape::test
