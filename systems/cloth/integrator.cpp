// Forces and symplectic Euler (method §3.3, §3.4); step order in integrator.hpp.
#include "systems/cloth/integrator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {

void add_spring_forces(const SpringPhase& springs, Real k, const Matrix3X& x, Matrix3X& force) {
    const std::size_t n = springs.size();
    const std::uint32_t* a = springs.a.data();
    const std::uint32_t* b = springs.b.data();
    const Real* rest = springs.rest_m.data();
    for (std::size_t s = 0; s < n; ++s) {
        const Vec3 d = x.col(b[s]) - x.col(a[s]);
        const Real length = d.norm();
        if (length <= Real(1e-12)) continue;  // coincident ends: no direction, no force
        const Vec3 f = (k * (length - rest[s]) / length) * d;
        force.col(a[s]) += f;
        force.col(b[s]) -= f;
    }
}

void integrate_particles(Matrix3X& x, Matrix3X& v, const VectorX& inv_mass, const Matrix3X& force,
                         Eigen::Index count, Real mass_scale, Real drag, const BodyMotion& body,
                         const Vec3& g, Real h) {
    const Vec3 a_b = body.acceleration_m_s2;
    const Real k = drag * mass_scale;
    for (Eigen::Index i = 0; i < count; ++i) {
        const Real w = inv_mass[i];
        if (w == 0) continue;  // pinned: follows the skin (method §3.5)
        const Real m = mass_scale / w;
        const Vec3 xi = x.col(i);
        const Vec3 v_b = body.velocity_m_s + body.angular_velocity_rad_s.cross(xi - body.center);
        const Vec3 v_rel = v.col(i) - v_b;
        // Paper eq. 2, in the body's frame.
        const Vec3 f = -m * a_b - k * (v_b + a_b * (h / 2)) - k * v_rel + m * g + force.col(i);
        // Symplectic Euler (§3.4) on world velocities: relative acceleration + frame acceleration.
        v.col(i) += h * (f / m + a_b);
        x.col(i) += h * v.col(i);
    }
}

Real stable_step_s(const Fabric& topology, const ClothMaterial& material, const VectorX& inv_mass,
                   ClothModel model) {
    const Eigen::Index n = static_cast<Eigen::Index>(topology.particle_count());
    const bool simplified = model == ClothModel::simplified;
    const Eigen::Index integrated = simplified ? static_cast<Eigen::Index>(topology.layer1_count) : n;
    const Real scale = simplified ? topology.layer1_mass_scale : Real(1);
    VectorX row_k = VectorX::Zero(n);
    auto add = [&](const SpringPhase& springs, Real k) {
        for (std::size_t s = 0; s < springs.size(); ++s) {
            const std::uint32_t a = springs.a[s], b = springs.b[s];
            const bool a_free = inv_mass[a] != 0 && a < integrated;
            const bool b_free = inv_mass[b] != 0 && b < integrated;
            row_k[a] += k * (b_free ? 2 : 1);
            row_k[b] += k * (a_free ? 2 : 1);
        }
    };
    if (simplified) {
        add(topology.warp1, material.stretch_k_N_m * scale);
        add(topology.weft1, material.stretch_k_N_m);
    } else {
        add(topology.warp1, material.stretch_k_N_m);
        add(topology.warp2, material.stretch_k_N_m);
        add(topology.weft, material.stretch_k_N_m);
        add(topology.shear, material.shear_k_N_m);
        add(topology.bend, material.bend_k_N_m);
    }
    Real lambda = 0;
    Real min_mass = std::numeric_limits<Real>::infinity();
    for (Eigen::Index i = 0; i < integrated; ++i) {
        if (inv_mass[i] == 0) continue;
        const Real m = scale / inv_mass[i];
        lambda = std::max(lambda, row_k[i] / m);
        min_mass = std::min(min_mass, m);
    }
    Real h = lambda > 0 ? Real(2) / std::sqrt(lambda) : std::numeric_limits<Real>::infinity();
    const Real drag = material.drag_N_s_m * scale;
    if (drag > 0 && std::isfinite(min_mass)) h = std::min(h, min_mass / drag);
    return h;
}

}  // namespace drape
