// Runs a per-garment function over every garment in parallel (TBB). Garments are
// independent (each reads the shared colliders and writes only itself), so the result is
// the same bytes whatever the number of threads.
#pragma once

#include <memory>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "components/garment.hpp"
#include "engine/core/registry.hpp"

namespace drape {

/// Garment pointers collected per run; kept by a system between runs so no allocation
/// happens once the scene is stable.
struct GarmentBatch {
    std::vector<Garment*> garments;
};

template <class F>
void for_each_garment(Registry& registry, GarmentBatch& batch, F&& f) {
    batch.garments.clear();
    registry.view<Garment>().each([&](Entity, Garment& g) {
        if (g.topology && g.x.cols() > 0) batch.garments.push_back(&g);
    });
    if (batch.garments.size() == 1) {
        f(*batch.garments.front());
        return;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, batch.garments.size()),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t i = range.begin(); i != range.end(); ++i) f(*batch.garments[i]);
                      });
}

}  // namespace drape
