// The substep rule (method §3.4); see substeps.hpp.
#include "drape/systems/cloth/substeps.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/systems/cloth/body.hpp"

namespace drape {
namespace {

// Box of the points: 16 at a time as 48 consecutive coordinates, each lane keeping the
// least and greatest of its coordinate (lane i holds coordinate i mod 3).
std::pair<Vec3, Vec3> bounds(const Matrix3X& x) {
    constexpr Real inf = std::numeric_limits<Real>::infinity();
    using Lanes = Eigen::Array<Real, 48, 1>;
    Lanes lo = Lanes::Constant(inf), hi = Lanes::Constant(-inf);
    const Real* d = x.data();
    const Eigen::Index n = x.cols();
    Eigen::Index p = 0;
    for (; p + 16 <= n; p += 16) {
        const Eigen::Map<const Lanes> block(d + 3 * p);
        lo = lo.min(block);
        hi = hi.max(block);
    }
    Vec3 low = Vec3::Constant(inf), high = Vec3::Constant(-inf);
    for (int i = 0; i < 48; ++i) {
        low[i % 3] = std::min(low[i % 3], lo[i]);
        high[i % 3] = std::max(high[i % 3], hi[i]);
    }
    for (; p < n; ++p) {
        low = low.cwiseMin(x.col(p));
        high = high.cwiseMax(x.col(p));
    }
    return {low, high};
}

}  // namespace

int garment_substeps(const Registry& registry, Garment& g, GarmentSolver& solver, double fixed_dt,
                     const ClothSolverSettings& s) {
    if (!g.fabric) return 1;
    prepare_solver(g, solver);
    solver.repair_rounds_left = std::max(0, s.repair_rounds_per_frame);
    if (s.fixed_substeps > 0) {
        g.counters.substeps_stability = g.counters.substeps_motion = s.fixed_substeps;
        return s.fixed_substeps;
    }
    const double cap = std::max(1, s.max_substeps);
    const bool paper = g.config.integrator == ClothIntegrator::paper;
    const double stability_cap = paper ? std::max(cap, double(s.max_stability_substeps)) : cap;
    const double h_bound = paper ? std::min(double(solver.drag_step_s), double(solver.spring_step_s)) : double(solver.drag_step_s);
    const double h_stable = h_bound * s.stability_safety;
    const double stability = h_stable > 0 ? std::ceil(fixed_dt / h_stable) : stability_cap;  // +inf: no bound, one substep

    // Fastest collider surface the garment can touch, relative to its anchor.
    double speed = 0;
    const GarmentBody& body = g.body;
    const EllipsoidCollider* anchor = body.anchor >= 0 && static_cast<std::size_t>(body.anchor) < body.colliders.size()
        ? registry.try_get<EllipsoidCollider>(body.colliders[static_cast<std::size_t>(body.anchor)]) : nullptr;
    // Colliders the garment can reach: those whose box comes within the candidate margin of
    // the garment's box (the same in both collision modes).
    const auto [x_low, x_high] = bounds(g.state.x);
    const Vec3 low = x_low.array() - g.config.material.candidate_margin_m;
    const Vec3 high = x_high.array() + g.config.material.candidate_margin_m;
    const Vec3 anchor_c = anchor ? Vec3(anchor->world.translation()) : Vec3::Zero();
    for (std::size_t e = 0; e < body.colliders.size() && e < 64; ++e) {
        const auto* c = registry.try_get<EllipsoidCollider>(body.colliders[e]);
        if (c == nullptr) continue;
        const Vec3 center = c->world.translation();
        const Vec3 half = c->world.linear().cwiseAbs().rowwise().sum();  // the unit sphere's box, mapped
        if (((center - half).array() > high.array()).any() || ((center + half).array() < low.array()).any()) continue;
        Vec3 dv = c->velocity_m_s;
        Vec3 dw = c->angular_velocity_rad_s;
        if (anchor) {
            dv -= anchor->velocity_m_s + anchor->angular_velocity_rad_s.cross(center - anchor_c);
            dw -= anchor->angular_velocity_rad_s;
        }
        const Real r_max = c->world.linear().colwise().norm().maxCoeff();
        const double u = double(dv.norm()) + double(dw.norm()) * double(r_max);
        if (std::isfinite(u)) speed = std::max(speed, u);
    }
    const double motion = s.max_surface_travel_m > 0 ? std::ceil(fixed_dt * speed / s.max_surface_travel_m) : 1;

    g.counters.substeps_stability = static_cast<int>(std::clamp(stability, 1.0, stability_cap));
    g.counters.substeps_motion = static_cast<int>(std::clamp(motion, 1.0, cap));
    return std::max(g.counters.substeps_stability, g.counters.substeps_motion);
}

}  // namespace drape
