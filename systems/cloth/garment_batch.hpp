// The garments of a registry gathered for one fixed step, and a per-garment function run
// over them in parallel (TBB). Garments are independent (each reads the shared colliders and
// writes only itself and its solver), so the result is the same bytes whatever the number
// of threads.
#pragma once

#include <vector>

#include "drape/components/garment.hpp"
#include "drape/engine/core/jobs.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/cloth/garment_solver.hpp"

namespace drape {

/// One garment and its solver.
struct GarmentWork {
    Garment* garment = nullptr;
    GarmentSolver* solver = nullptr;
};

/// Garments gathered per fixed step; kept by the cloth step between runs so that no
/// allocation happens once the scene is stable.
struct GarmentBatch {
    std::vector<GarmentWork> items;
    std::vector<Entity> missing_solver;

    /// Every garment with a fabric and particles, each with its solver (created where missing).
    void gather(Registry& registry) {
        missing_solver.clear();
        registry.view<Garment>().each([&](Entity e, Garment&) {
            if (!registry.has<GarmentSolver>(e)) missing_solver.push_back(e);
        });
        for (Entity e : missing_solver) registry.emplace<GarmentSolver>(e);
        items.clear();
        registry.view<Garment, GarmentSolver>().each([&](Entity, Garment& g, GarmentSolver& s) {
            if (g.fabric && g.state.x.cols() > 0) items.push_back({&g, &s});
        });
    }

    /// Runs f(garment, solver) for every item, on the job system when there is more than one.
    template <class F>
    void for_each(F&& f) const {
        if (items.size() == 1) {
            f(*items.front().garment, *items.front().solver);
            return;
        }
        job_system().parallel_for(items.size(), [&](std::size_t i) { f(*items[i].garment, *items[i].solver); });
    }
};

}  // namespace drape
