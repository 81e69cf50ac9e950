// A big garment's work in fixed parts; see garment_parts.hpp.
#include "systems/cloth/garment_parts.hpp"

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

std::vector<std::uint32_t> line_band_edges(std::uint32_t lines, std::uint32_t stride, std::uint32_t bands) {
    std::vector<std::uint32_t> edges(bands + 1, lines);
    const std::uint32_t step = 8 * std::max(1u, stride);
    bool aligned = true;
    for (std::uint32_t k = 0; k < bands; ++k) {
        const std::uint32_t even = lines * k / bands;
        edges[k] = (even + step / 2) / step * step;
        aligned = aligned && (k == 0 || edges[k] > edges[k - 1]) && edges[k] < lines;
    }
    if (!aligned)
        for (std::uint32_t k = 0; k < bands; ++k) edges[k] = lines * k / bands;
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
    parts.row_band.assign(n, 0);
    parts.line_band.assign(n, 0);
    const std::vector<std::uint32_t> edges = line_band_edges(lines, t.weft_stride, count);
    parts.lines.resize(count);
    for (std::uint32_t k = 0; k < count; ++k) parts.lines[k] = {edges[k], edges[k + 1]};
    for (std::uint32_t line = 0; line < lines; ++line)
        for (std::uint32_t row = 0; row < m; ++row) {
            const std::uint32_t p = t.grid[line * m + row];
            parts.row_band[p] = row * count / m;
            parts.line_band[p] = line_band_of(edges, line);
        }
    for (std::uint32_t k = 0; k < count; ++k) {
        parts.row_runs.push_back(runs_of(parts.row_band, k, n));
        parts.integrated_runs.push_back(runs_of(parts.row_band, k, integrated));
        parts.line_runs.push_back(runs_of(parts.line_band, k, n));
        // Whole blocks of 64 (the collision's detection and list blocks).
        const auto edge = [&](std::uint32_t j) { return static_cast<Eigen::Index>(std::min(n, (n * j / count + 63) / 64 * 64)); };
        parts.particles.push_back({k == 0 ? 0 : edge(k), k + 1 == count ? n : edge(k + 1)});
    }
    parts.weft_entries.resize(count);
    for (std::size_t e = 0; e < t.weft_particle.size(); ++e)
        parts.weft_entries[parts.row_band[t.weft_particle[e]]].push_back(static_cast<std::uint32_t>(e));
    return parts;
}

}  // namespace drape
