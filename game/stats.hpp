// The run statistics `drape play --stats FILE.json` writes (docs/scenes.md, "Stats file"):
//
//   {"frames": N, "sim_dt_s": S,
//    "characters": [{"file", "clip", "height_m"}],
//    "systems": {NAME: {"runs", "skips", "mean_ms", "p50_ms", "p95_ms", "max_ms"}},
//    "garments": [{"particles",
//                  "strain": {"max", "p99"},
//                  "penetration_m": {"after_frame_max", "before_response_max", "within_give_max"},
//                  "pins_inside_m", "rise_above_pins_m", "nonfinite", "resets",
//                  "collision_tests_per_frame", "max_strain", "max_penetration_m"}]}
//
// `sim_dt_s` is the fixed simulation step. Garment figures are measured after every whole
// frame (systems/cloth/garment_quality.hpp) and are the worst seen over the run, except
// `strain.p99`: the 99th percentile over every spring of every frame. `max_strain` and
// `max_penetration_m` repeat `strain.max` and `penetration_m.before_response_max`.
// Penetration counts the depth past an ellipsoid's give (EllipsoidCollider::give_m);
// `within_give_max` is the deepest a free particle lay inside a giving ellipsoid within it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/profiler.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/cloth/garment_quality.hpp"

namespace drape {

/// One garment over a run.
struct GarmentStats {
    std::uint64_t particles = 0;
    double strain_max = 0;               ///< Largest strain of a structural spring with a free end after a frame.
    double strain_p99 = 0;               ///< 99th percentile of those strains over every frame.
    double penetration_after_frame_m = 0;///< Deepest free particle inside an ellipsoid after a frame (past its give).
    double within_give_m = 0;            ///< Deepest free particle inside a giving ellipsoid, within its give, after a frame.
    double penetration_before_response_m = 0; ///< Deepest penetration the collision found before moving a particle out.
    double pins_inside_m = 0;            ///< Deepest pinned particle inside an ellipsoid after a frame.
    double rise_above_pins_m = 0;        ///< Highest free particle above the highest pin after a frame.
    std::uint64_t nonfinite = 0;         ///< Non-finite values the cloth found and reset, plus any left in x or v.
    std::uint64_t resets = 0;            ///< Garment resets during the run (non-finite state, teleports, requests).
    double collision_tests_per_frame = 0;///< Particle-ellipsoid tests per rendered frame, mean.
};

/// A character of the run: its file, the clip it plays, its height.
struct CharacterStats {
    std::string file;
    std::string clip;
    double height_m = 0;
};

struct RunStats {
    std::uint64_t frames = 0;
    double sim_dt_s = 0;
    std::vector<CharacterStats> characters;  ///< In scene order.
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
        GarmentStats worst;
        std::shared_ptr<StrainHistogram> strains = std::make_shared<StrainHistogram>();
        std::uint64_t tests_at_start = 0, resets_at_start = 0;
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
