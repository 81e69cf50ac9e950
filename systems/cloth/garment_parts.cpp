// A big garment's work in fixed parts; see garment_parts.hpp.
#include "drape/systems/cloth/garment_parts.hpp"

#include <algorithm>

namespace drape {
namespace {

// Runs of the particles whose band is `band`.
std::vector<ParticleRun> runs_of(const std::vector<std::uint32_t>& band_of, std::uint32_t band, Eigen::Index end) {
    std::vector<ParticleRun> runs;
    for (Eigen::Index p = 0; p < end; ++p) {
        if (band_of[static_cast<std::size_t>(p)] != band) continue;
        if (!runs.empty() && runs.back().end == p)
            runs.back().end = p + 1;
        else
            runs.push_back({p, p + 1});
    }
    return runs;
}

}  // namespace

std::uint32_t part_count(std::uint32_t lines, std::uint32_t rows) noexcept {
    return std::max(1u, std::min({max_parts, lines * rows / part_particles, lines, rows}));
}

std::vector<std::uint32_t> line_band_edges(std::uint32_t lines, std::uint32_t bands) {
    std::vector<std::uint32_t> edges(bands + 1);
    for (std::uint32_t k = 0; k <= bands; ++k) edges[k] = lines * k / bands;
    return edges;
}

std::uint32_t line_band_of(const std::vector<std::uint32_t>& edges, std::uint32_t line) noexcept {
    return static_cast<std::uint32_t>(std::upper_bound(edges.begin(), edges.end() - 1, line) - edges.begin()) - 1;
}

GarmentParts make_parts(const Fabric& t, ClothModel model, Eigen::Index integrated) {
    GarmentParts parts;
    const std::uint32_t n = static_cast<std::uint32_t>(t.particle_count());
    const std::uint32_t lines = t.warp_lines, m = t.particles_per_line;
    const std::uint32_t count = model == ClothModel::simplified ? std::max(1u, t.line_bands) : 1;
    parts.count = count;
    const std::vector<std::uint32_t> edges = line_band_edges(lines, count);
    parts.band.assign(n, 0);
    for (std::uint32_t line = 0; line < lines; ++line)
        for (std::uint32_t row = 0; row < m; ++row) parts.band[t.grid[line * m + row]] = line_band_of(edges, line);
    parts.weft_entries.resize(count);
    for (std::uint32_t k = 0; k < count; ++k) {
        parts.lines.emplace_back(edges[k], edges[k + 1]);
        parts.runs.push_back(runs_of(parts.band, k, n));
        parts.integrated_runs.push_back(runs_of(parts.band, k, integrated));
    }
    for (std::size_t e = 0; e < t.weft_particle.size(); ++e) {
        const std::uint32_t k = parts.band[t.weft_particle[e]];
        if (parts.band[t.weft_left[e]] == k && parts.band[t.weft_right[e]] == k)
            parts.weft_entries[k].push_back(static_cast<std::uint32_t>(e));
        else
            parts.edge_weft_entries.push_back(static_cast<std::uint32_t>(e));
    }
    return parts;
}

}  // namespace drape
