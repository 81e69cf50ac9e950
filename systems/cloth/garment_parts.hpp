// A big garment's own work in fixed parts that threads can take (docs/cloth.md "Threads").
//
// A garment of many particles is cut, once, into `count` parts of each of three kinds, by
// its grid alone (never by the number of threads):
//   - row bands: the weft springs, which join particles of one row, the prediction of the
//     band's integrated particles and the carriage of its layer-2 particles (whose chord
//     ends are in the same row);
//   - line bands: the warp springs, which join particles of one line, the tethers and the
//     warp limit, both of which run along one line;
//   - particle ranges (whole blocks of 64): collision with candidate lists of their own,
//     and the velocities.
// Parts of one kind share no particle, so they run at the same time in any order, and a
// stage of one kind only starts when the stage before it has finished: each part does the
// same arithmetic whichever thread takes it, and the garment ends every step in the same
// bytes on one thread or many (tested). One part of each kind is the whole garment, in the
// solver's order: a garment below `part_particles` x 2, and the classic model (its shear and
// bend springs cross rows and lines), stay in one part.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include "components/garment.hpp"
#include "engine/core/math.hpp"

namespace drape {

/// Particles per part: a garment is cut into n / part_particles parts (at most max_parts).
/// The 10,080-particle dress makes two; the 837-particle skirt one.
inline constexpr std::uint32_t part_particles = 5000;
inline constexpr std::uint32_t max_parts = 8;

/// Parts of a grid of `lines` x `rows` particles: one per part_particles, at most max_parts,
/// lines or rows. The fabric stores its particles by this many line bands (line_band_of).
[[nodiscard]] std::uint32_t part_count(std::uint32_t lines, std::uint32_t rows) noexcept;

/// Line bands of a grid of `lines` lines, every `stride`-th of them layer 1: band k holds
/// lines [edges[k], edges[k + 1]). The edges fall on whole multiples of 8 lines of each
/// layer where the bands stay non-empty, so that a band's rows of warp springs run in whole
/// 8-lane vectors (a 20-line band would end each of its strips in 4 scalar lanes).
[[nodiscard]] std::vector<std::uint32_t> line_band_edges(std::uint32_t lines, std::uint32_t stride, std::uint32_t bands);

/// The band of `line` by its edges.
[[nodiscard]] std::uint32_t line_band_of(const std::vector<std::uint32_t>& edges, std::uint32_t line) noexcept;

/// A run of consecutive particles [begin, end).
struct ParticleRun {
    Eigen::Index begin = 0, end = 0;
};

/// Which band kind a spring set is cut by.
enum class BandKind : std::uint8_t { rows, lines };

struct GarmentParts {
    std::size_t count = 1;
    std::vector<std::uint32_t> row_band;               ///< Per particle: its row band.
    std::vector<std::uint32_t> line_band;              ///< Per particle: its line band.
    std::vector<std::vector<ParticleRun>> row_runs;    ///< Per row band: its particles.
    std::vector<std::vector<ParticleRun>> integrated_runs;  ///< Per row band: its integrated particles.
    std::vector<std::vector<std::uint32_t>> weft_entries;   ///< Per row band: its Fabric::weft_particle entries.
    std::vector<std::vector<ParticleRun>> line_runs;   ///< Per line band: its particles.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> lines;  ///< Per line band: its lines [first, end).
    std::vector<ParticleRun> particles;                ///< Per particle range.
};

/// The parts of `fabric` for `model` (fabric.line_bands of them for the simplified model, one
/// for the classic), `integrated` the particles [0, integrated) integrated.
[[nodiscard]] GarmentParts make_parts(const Fabric& fabric, ClothModel model, Eigen::Index integrated);

/// Calls f(k) for every part k in [0, count): on the calling thread for one part, else as
/// TBB tasks (one part each) on the threads TBB has, returning when all are done.
template <class F>
void for_each_part(std::size_t count, F&& f) {
    if (count == 1) {
        f(std::size_t(0));
        return;
    }
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, count, 1),
        [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t k = r.begin(); k != r.end(); ++k) f(k);
        },
        tbb::static_partitioner());
}

}  // namespace drape
