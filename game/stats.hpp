// The run statistics `drape play --stats FILE.json` writes (docs/scenes.md, "Stats file"):
//
//   {"frames": N, "sim_dt_s": S,
//    "systems": {NAME: {"runs", "skips", "mean_ms", "p50_ms", "p95_ms", "max_ms"}},
//    "garments": [{"particles", "max_strain", "max_penetration_m", "nonfinite",
//                  "collision_tests_per_frame"}]}
//
// `sim_dt_s` is the fixed simulation step. Garment figures are the worst seen over the
// run: `GarmentWatch::sample` reads each garment's counters (components/garment.hpp)
// after every frame and also scans its particles for non-finite values itself.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "engine/core/error.hpp"
#include "engine/core/profiler.hpp"
#include "engine/core/registry.hpp"

namespace drape {

/// One garment over a run.
struct GarmentStats {
    std::uint64_t particles = 0;
    double max_strain = 0;               ///< Largest spring length / rest - 1 seen.
    double max_penetration_m = 0;        ///< Deepest particle penetration into an ellipsoid seen (before response).
    std::uint64_t nonfinite = 0;         ///< Non-finite values the cloth found and reset, plus any left in x or v.
    double collision_tests_per_frame = 0;///< Particle-ellipsoid tests per rendered frame, mean.
};

struct RunStats {
    std::uint64_t frames = 0;
    double sim_dt_s = 0;
    std::vector<SystemStats> systems;    ///< In scheduler order.
    std::vector<GarmentStats> garments;  ///< In scene order.
};

/// Follows garments over a run.
class GarmentWatch {
public:
    GarmentWatch() = default;
    /// Starts watching these Garment entities (scene order); counts before now are not the run's.
    GarmentWatch(const Registry& registry, std::vector<Entity> garments);
    /// Reads counters and particles after a frame.
    void sample(const Registry& registry);
    /// Per garment, over `frames` frames sampled so far.
    [[nodiscard]] std::vector<GarmentStats> result(const Registry& registry) const;
    [[nodiscard]] std::uint64_t frames() const noexcept { return m_frames; }

private:
    struct Track {
        Entity entity;
        double max_strain = 0, max_penetration_m = 0;
        std::uint64_t nonfinite_seen = 0;    ///< Particles found non-finite by sample().
        std::uint64_t tests_at_start = 0;
    };
    std::vector<Track> m_tracks;
    std::uint64_t m_frames = 0;
};

/// Systems of a profiler (registered slots) as run statistics.
[[nodiscard]] RunStats make_run_stats(const FrameProfiler& profiler, double sim_dt_s,
                                      const GarmentWatch& watch, const Registry& registry);

/// The stats JSON text.
[[nodiscard]] std::string stats_json(const RunStats& stats);

/// Writes the stats JSON through a temporary file and a rename: no partial file on error.
[[nodiscard]] Result<void> write_stats(const RunStats& stats, const std::filesystem::path& file);

/// Writes text to a file atomically (temporary next to it, then rename). The error names the file.
[[nodiscard]] Result<void> write_file_atomically(const std::filesystem::path& file, std::string_view text);

}  // namespace drape
