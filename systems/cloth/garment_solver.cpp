// The cloth module's per-garment caches; see garment_solver.hpp.
#include "drape/systems/cloth/garment_solver.hpp"

#include <algorithm>
#include <limits>

#include "drape/systems/cloth/integrator.hpp"

namespace drape {

void invalidate(GarmentSolver& s) {
    s.configured = false;
    s.lists.valid = false;
}

namespace {

// The solver's masses and drags: the state's (1 / inverse mass, material drag x area), each
// particle's own. In the simplified model a layer-2 particle is carried by its layer-1
// neighbours in the prediction (weft.hpp) and keeps its own mass in the constraint rounds:
// adding it to its neighbours as well would count it twice there (and the prediction, whose
// drag over mass is the material's per area either way, does not need it).
void derive_masses(const Garment& g, GarmentSolver& s) {
    const VectorX& w = g.state.inv_mass;
    s.inv_mass = w;
    s.drag_N_s_m = g.config.material.drag_N_s_m3 * g.fabric->area_m2;
}

SpringSet spring_set(const SpringPhase& phase, const VectorX& area, Real modulus, bool limited, const GarmentParts& parts) {
    SpringSet set;
    set.springs = &phase;
    set.strips = split_strips(spring_strips(phase), parts.band, parts.count);
    set.compliance = spring_compliance(phase, area, modulus);
    set.lambda.assign(phase.size(), 0);
    set.limited = limited;
    return set;
}

// The fabric's bend springs along its weft rows (each particle to the second beside it):
// those whose ends lie on two lines (`line`: each particle's), in the fabric's order.
SpringPhase weft_bends(const Fabric& t, const std::vector<std::uint32_t>& line) {
    SpringPhase phase;
    for (std::size_t k = 0; k < t.bend.size(); ++k)
        if (line[t.bend.a[k]] != line[t.bend.b[k]]) phase.add(t.bend.a[k], t.bend.b[k], t.bend.rest_m[k]);
    return phase;
}

}  // namespace

void prepare_solver(const Garment& g, GarmentSolver& s) {
    const Fabric& t = *g.fabric;
    const GarmentState& state = g.state;
    const Eigen::Index n = static_cast<Eigen::Index>(t.particle_count());
    const bool simplified = g.config.model == ClothModel::simplified;
    if (!s.configured || !(s.built_for == g.config) || s.built_fabric != &t || s.built_pins != state.pins.size()) {
        if (s.configured && s.built_for.material.candidate_margin_m != g.config.material.candidate_margin_m) s.lists.valid = false;
        const ClothMaterial& m = g.config.material;
        // Warp lines solved directly (docs/cloth.md "Warp lines solved directly"): the shipped
        // integrator's option.
        const bool lines = g.config.warp_solve == WarpSolve::lines && g.config.integrator == ClothIntegrator::shipped;
        s.integrated = simplified ? static_cast<Eigen::Index>(t.layer1_count) : n;
        derive_masses(g, s);
        // Stiffness from the cloth's moduli and the areas the springs' particles stand for:
        // a layer-1 particle of the simplified model stands for its weft shares too.
        VectorX area = t.area_m2;
        if (simplified)
            for (std::size_t k = 0; k < t.weft_particle.size(); ++k) {
                const Real share = t.weft_t[k];
                area[t.weft_left[k]] += (1 - share) * t.area_m2[t.weft_particle[k]];
                area[t.weft_right[k]] += share * t.area_m2[t.weft_particle[k]];
            }
        s.parts = make_parts(t, g.config.model, s.integrated);
        const GarmentParts& parts = s.parts;
        s.below.resize(static_cast<std::size_t>(n));
        s.above.resize(static_cast<std::size_t>(n));
        s.grid_line.resize(static_cast<std::size_t>(n));
        s.grid_row.resize(static_cast<std::size_t>(n));
        s.repair_part.resize(static_cast<std::size_t>(n));
        const std::uint32_t rows = t.particles_per_line;
        for (std::uint32_t line = 0; line < t.warp_lines; ++line)
            for (std::uint32_t row = 0; row < rows; ++row) {
                s.grid_line[t.grid[line * rows + row]] = line;
                s.grid_row[t.grid[line * rows + row]] = row;
                s.repair_part[t.grid[line * rows + row]] = static_cast<std::uint32_t>(line % parts.count);
                s.below[t.grid[line * rows + row]] = t.grid[line * rows + std::min(row + 1, rows - 1)];
                s.above[t.grid[line * rows + row]] = t.grid[line * rows + (row > 0 ? row - 1 : 0)];
            }
        s.springs.clear();
        s.weft_bend.reset();
        if (simplified && m.weft_bend != 0) {
            // Bending along the weft rows first, as the classic model's bend springs: the
            // structural springs and their limit have the last word (docs/cloth.md "Weft bending").
            s.weft_bend = std::make_shared<const SpringPhase>(weft_bends(t, s.grid_line));
            s.springs.push_back(spring_set(*s.weft_bend, area, m.bend_N_m, false, parts));
        }
        if (simplified) {
            // Weft springs, then the warp: layer 1's (with the areas its particles stand for;
            // with lines their own, layer 2's lines carrying their own weight), then layer 2's.
            s.springs.push_back(spring_set(t.weft, t.area_m2, m.stretch_N_m, true, parts));
            s.springs.push_back(spring_set(t.warp1, lines ? t.area_m2 : area, m.stretch_N_m, true, parts));
            s.springs.push_back(spring_set(t.warp2, t.area_m2, m.stretch_N_m, true, parts));
        } else {
            // Shear and bend first: the structural springs and their limit have the last word.
            s.springs.push_back(spring_set(t.shear, area, m.shear_N_m, false, parts));
            s.springs.push_back(spring_set(t.bend, area, m.bend_N_m, false, parts));
            s.springs.push_back(spring_set(t.weft, area, m.stretch_N_m, true, parts));
            s.springs.push_back(spring_set(t.warp1, area, m.stretch_N_m, true, parts));
            s.springs.push_back(spring_set(t.warp2, area, m.stretch_N_m, true, parts));
        }
        // The paper's integrator: its masses, its explicit springs and their stability bound.
        s.paper_inv_mass = s.inv_mass;
        if (simplified)
            for (Eigen::Index p = 0; p < n; ++p)
                if (s.paper_inv_mass[p] != 0) s.paper_inv_mass[p] = 1 / (m.areal_density_kg_m2 * area[p]);
        s.explicit_sets.clear();
        s.provot_first.clear();
        s.provot_then.clear();
        for (std::size_t k = 0; k < s.springs.size(); ++k) {
            const SpringPhase* phase = s.springs[k].springs;
            if (!simplified || phase == &t.warp1) s.explicit_sets.push_back(k);
            if (!s.springs[k].limited) continue;
            (!simplified || phase == &t.warp1 ? s.provot_first : s.provot_then).push_back(k);
        }
        if (lines)
            for (SpringSet& set : s.springs)
                if (set.springs == &t.warp1 || set.springs == &t.warp2) (void)line_chains(set);
        s.spring_step_s = spring_step_limit_s(s.springs, s.explicit_sets, s.paper_inv_mass);
        s.warp_rest_above = warp_rest_above(t);
        s.weft_rest_right = weft_rest_right(t);
        Tethers tethers = build_tethers(t, state.inv_mass, s.warp_rest_above);
        if (lines)  // the warp limit's slack, so that a line can stretch as far as its springs may
            for (Real& l : tethers.length_m) l *= 1 + m.limit_share * m.strain_limit;
        s.tethers = split_tethers(tethers, parts.band, parts.count);
        s.part_counters.assign(parts.count, PartCounters{});
        s.line_steps.assign(parts.count, 0);
        s.pushed.assign(parts.count, {});
        s.part_scratch.resize(parts.count);
        s.drag_step_s = drag_step_limit_s(s.inv_mass, s.drag_N_s_m, s.integrated);
        s.built_for = g.config;
        s.built_fabric = &t;
        s.built_pins = state.pins.size();
        s.configured = true;
    }
    if (s.warp_moves.cols() != n) s.warp_moves = Matrix3X::Zero(3, n);
    if (s.weft_moves.cols() != n) s.weft_moves = Matrix3X::Zero(3, n);
    if (s.repair_warp_moves.cols() != n) s.repair_warp_moves = Matrix3X::Zero(3, n);
    if (s.repair_weft_moves.cols() != n) s.repair_weft_moves = Matrix3X::Zero(3, n);
    if (s.repair_slack_m.size() != n) s.repair_slack_m = VectorX::Zero(n);
    if (s.repair_lists.size() != static_cast<std::size_t>(n)) s.repair_lists.assign(static_cast<std::size_t>(n), 0);
    if (s.x_round.cols() != n) s.x_round = Matrix3X::Zero(3, n);
    if (s.x_start.cols() != n) s.x_start = Matrix3X::Zero(3, n);
    if (s.push.cols() != n) s.push = Matrix3X::Zero(3, n);
    if (s.x_rows.cols() != n) s.x_rows = Matrix3XRows::Zero(3, n);
    if (s.last_collided.size() != static_cast<std::size_t>(n)) s.last_collided.assign(static_cast<std::size_t>(n), 0);
    if (s.contacts.size() != static_cast<std::size_t>(n)) s.contacts.assign(static_cast<std::size_t>(n), 0);
}

}  // namespace drape
