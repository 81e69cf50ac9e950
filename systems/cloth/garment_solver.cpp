// The cloth module's per-garment caches; see garment_solver.hpp.
#include "systems/cloth/garment_solver.hpp"

#include "systems/cloth/integrator.hpp"

namespace drape {

void invalidate(GarmentSolver& s) {
    s.configured = false;
    s.lists.valid = false;
}

void prepare_solver(const Garment& g, GarmentSolver& s) {
    const Fabric& t = *g.fabric;
    const GarmentState& state = g.state;
    const Eigen::Index n = static_cast<Eigen::Index>(t.particle_count());
    if (!s.configured || !(s.built_for == g.config)) {
        // What depends on the model and the material: the stability bounds and the lists' margin.
        s.stable_step_s[0] = stable_step_s(t, g.config.material, state.inv_mass, ClothModel::simplified);
        s.stable_step_s[1] = stable_step_s(t, g.config.material, state.inv_mass, ClothModel::classic);
        if (s.configured && s.built_for.material.candidate_margin_m != g.config.material.candidate_margin_m)
            s.lists.valid = false;
        s.built_for = g.config;
        s.configured = true;
    }
    if (s.force.cols() != n) s.force = Matrix3X::Zero(3, n);
    if (s.normals.cols() != static_cast<Eigen::Index>(t.layer1_count)) s.normals = Matrix3X::Zero(3, t.layer1_count);
    if (s.plane_normal.cols() != n) s.plane_normal = Matrix3X::Zero(3, n);
    if (s.movable.size() != static_cast<std::size_t>(n)) {
        s.movable.resize(static_cast<std::size_t>(n));
        s.movable_weft.resize(static_cast<std::size_t>(n));
        for (Eigen::Index i = 0; i < n; ++i) {
            const std::size_t k = static_cast<std::size_t>(i);
            s.movable[k] = state.inv_mass[i] != 0;
            s.movable_weft[k] = state.inv_mass[i] != 0 && t.layer[k] == 2;
        }
    }
    if (s.last_collided.size() != static_cast<std::size_t>(n)) s.last_collided.assign(static_cast<std::size_t>(n), 0);
}

}  // namespace drape
