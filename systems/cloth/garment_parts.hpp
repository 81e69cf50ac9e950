// A big garment's own work in fixed parts that threads can take (docs/cloth.md "Threads").
//
// A garment of many particles is cut, once, by its grid alone (never by the number of
// threads), into `count` bands of neighbouring warp lines, and the fabric stores each
// band's particles together (Fabric::line_bands). A band is a part of every stage: the
// prediction of its integrated particles, the carriage of its layer-2 particles, its
// springs, tethers and warp limit (all of which run along its lines or between them), its
// collision with candidate lists of its own, and its velocities. What joins two bands, the
// weft springs across a band edge and the layer-2 particles whose chord crosses one, is
// done on one thread between the stages. Bands share no particle, so they run at the same
// time in any order, and a stage only starts when the one before has finished: each band
// does the same arithmetic whichever thread takes it, and the garment ends every step in
// the same bytes on one thread or many (tested). Each thread keeps its band's particles
// in its own cache from stage to stage. A garment below part_particles x 2, and the
// classic model (its shear and bend springs cross bands), stay in one band, in the solver's
// order.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "drape/components/garment.hpp"
#include "drape/engine/core/jobs.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// Particles per part: a garment is cut into n / part_particles parts (at most max_parts).
/// The 10,080-particle dress makes two; the 837-particle skirt one.
inline constexpr std::uint32_t part_particles = 5000;
inline constexpr std::uint32_t max_parts = 8;

/// Parts of a grid of `lines` x `rows` particles: one per part_particles, at most max_parts,
/// lines or rows. The fabric stores its particles by this many line bands (line_band_of).
[[nodiscard]] std::uint32_t part_count(std::uint32_t lines, std::uint32_t rows) noexcept;

/// The first line of each of `bands` bands of `lines` lines, and `lines` at the end.
[[nodiscard]] std::vector<std::uint32_t> line_band_edges(std::uint32_t lines, std::uint32_t bands);

/// The band of `line` by its edges.
[[nodiscard]] std::uint32_t line_band_of(const std::vector<std::uint32_t>& edges, std::uint32_t line) noexcept;

/// A run of consecutive particles [begin, end).
struct ParticleRun {
    Eigen::Index begin = 0, end = 0;
};

struct GarmentParts {
    std::size_t count = 1;
    std::vector<std::uint32_t> band;                          ///< Per particle: its band.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> lines;  ///< Per band: its lines [first, end).
    std::vector<std::vector<ParticleRun>> runs;               ///< Per band: its particles.
    std::vector<std::vector<ParticleRun>> integrated_runs;    ///< Per band: its integrated particles.
    std::vector<std::vector<std::uint32_t>> weft_entries;     ///< Per band: Fabric::weft_particle entries whose chord is in it.
    std::vector<std::uint32_t> edge_weft_entries;             ///< The entries whose chord crosses a band edge.
};

/// The parts of `fabric` for `model` (fabric.line_bands of them for the simplified model, one
/// for the classic), `integrated` the particles [0, integrated) integrated.
[[nodiscard]] GarmentParts make_parts(const Fabric& fabric, ClothModel model, Eigen::Index integrated);

/// Calls f(k) for every part k in [0, count): in order on the calling thread for one part
/// or when the job system runs one thread at a time, else on the job system
/// (engine/core/jobs.hpp: TBB's unless the game installed its own), returning when all are
/// done.
template <class F>
void for_each_part(std::size_t count, F&& f) {
    JobSystem& jobs = job_system();
    if (count == 1 || jobs.max_concurrency() == 1) {
        for (std::size_t k = 0; k < count; ++k) f(k);
        return;
    }
    jobs.parallel_for(count, [&](std::size_t k) { f(k); });
}

}  // namespace drape
