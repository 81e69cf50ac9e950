// The run statistics `drape play --stats FILE.json` writes (docs/scenes.md, "Stats file"):
//
//   {"frames": N, "sim_dt_s": S,
//    "characters": [{"file", "clip", "height_m"}],
//    "systems": {NAME: {"runs", "skips", "mean_ms", "p50_ms", "p95_ms", "max_ms"}},
//    "garments": [{"particles",
//                  "strain": {"max", "p99", "pinned_max",
//                             "worst": {"frame", "spring", "line", "row", "rows", "body_part",
//                                       "part_thickness_m", "straddles"}},
//                  "penetration_m": {"after_frame_max", "before_response_max", "within_give_max",
//                                    "below_ground_max"},
//                  "skin_penetration_m": {"p99", "max", "share"},
//                  "pins_inside_m", "rise_above_pins_m", "speed_max_m_s", "nonfinite", "resets",
//                  "collision_tests_per_frame", "line_steps_per_frame", "max_strain",
//                  "max_penetration_m"}]}
//
// `sim_dt_s` is the fixed simulation step. Garment figures are measured after every whole
// frame (systems/cloth/garment_quality.hpp) and are the worst seen over the run, except
// `strain.p99`: the 99th percentile over every spring of every frame. `max_strain` and
// `max_penetration_m` repeat `strain.max` and `penetration_m.before_response_max`.
// `strain.worst` says where the run's worst spring was when it was worst (SpringPlace): the
// frame, "warp" or "weft", its first end's line and row (0 at the fitting zone) of `rows`,
// the region of the ellipsoid nearest its middle and that ellipsoid's smallest radius, and
// whether it straddled it; null when no spring was measured.
// Penetration counts the depth past an ellipsoid's give (EllipsoidCollider::give_m);
// `within_give_max` is the deepest a free particle lay inside a giving ellipsoid within it;
// `below_ground_max` the deepest a free particle lay under the floor (the scene's `ground`).
// `skin_penetration_m` is cloth behind the character's skin mesh (game/skin_penetration.hpp):
// p99 and max of the depths of the free particles found behind it after each frame, and
// their share of all free particles over every frame; null when not measured (`drape play`
// measures it with --stats). `speed_max_m_s` is the fastest free particle's stored velocity
// after a frame (in the world), the speed the next step starts it with.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/profiler.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/cloth/garment_quality.hpp"

namespace drape {

/// Where a run's worst spring was when it was worst (systems/cloth/garment_quality.hpp
/// SpringPlace, with the nearest ellipsoid's body region).
struct WorstSpring {
    bool seen = false;              ///< A spring was measured.
    std::uint64_t frame = 0;        ///< The frame it was worst after (1: the first sampled).
    bool weft = false;              ///< A weft spring, else a warp spring.
    std::uint32_t line = 0;         ///< Warp line of its first end.
    std::uint32_t row = 0;          ///< Row of its first end, 0 at the fitting zone.
    std::uint32_t rows = 0;         ///< Rows of the garment.
    std::string body_part = {};     ///< Region of the ellipsoid nearest its middle (body_region_name); empty: none.
    double part_thickness_m = 0;    ///< That ellipsoid's smallest radius.
    bool straddles = false;         ///< Its chord passed through that ellipsoid.
};

/// `strain.worst` of the stats file: {"frame", "spring", "line", "row", "rows", "body_part",
/// "part_thickness_m", "straddles"}, or null when no spring was measured.
[[nodiscard]] nlohmann::json worst_spring_json(const WorstSpring& worst);

/// One garment over a run.
struct GarmentStats {
    std::uint64_t particles = 0;
    double strain_max = 0;               ///< Largest strain of a structural spring with a free end after a frame.
    double strain_p99 = 0;               ///< 99th percentile of those strains over every frame.
    double compression_min = 1;          ///< Shortest such spring over its rest length after a frame, over the run.
    double pinned_strain_max = 0;        ///< Largest strain of a spring between two pinned particles after a frame (the fitting zone as the skin carries it; not in strain_max).
    double penetration_after_frame_m = 0;///< Deepest free particle inside an ellipsoid after a frame (past its give).
    double within_give_m = 0;            ///< Deepest free particle inside a giving ellipsoid, within its give, after a frame.
    double penetration_before_response_m = 0; ///< Deepest penetration the collision found before moving a particle out.
    double pins_inside_m = 0;            ///< Deepest pinned particle inside an ellipsoid after a frame.
    double below_ground_m = 0;           ///< Deepest free particle below the floor after a frame (0 without one).
    bool skin_measured = false;          ///< The depths behind the skin mesh below were measured (GarmentWatch with skin).
    double skin_penetration_p99_m = 0;   ///< 99th percentile of the depth behind the skin, over the particles behind it in every frame.
    double skin_penetration_max_m = 0;   ///< Deepest free particle behind the skin after a frame.
    double skin_penetration_share = 0;   ///< Share of free particles behind the skin, over every frame.
    double rise_above_pins_m = 0;        ///< Highest free particle above the highest pin after a frame.
    double speed_max_m_s = 0;            ///< Fastest free particle's stored velocity after a frame (world), m/s.
    std::uint64_t nonfinite = 0;         ///< Non-finite values the cloth found and reset, plus any left in x or v.
    std::uint64_t resets = 0;            ///< Garment resets during the run (non-finite state, teleports, requests).
    double collision_tests_per_frame = 0;///< Particle-ellipsoid tests per rendered frame, mean.
    double line_steps_per_frame = 0;     ///< Newton steps of the warp line solves per rendered frame, mean (0: rounds).
    int repair_rounds_max = 0;           ///< Most contact repair rounds in one frame.
    std::uint64_t budget_hits = 0;       ///< Substeps whose contact repair ran out of its round budget.
    double substeps_mean = 0;            ///< Substeps of the frame's last fixed step, mean over the frames.
    int substeps_max = 0;                ///< ... and the most.
    WorstSpring worst_spring = {};       ///< Where the spring of strain_max was.
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
    /// With `skin_every` > 0, also how deep cloth lies behind the skin mesh
    /// (game/skin_penetration.hpp), after every `skin_every`-th frame.
    GarmentWatch(const Registry& registry, std::vector<Entity> garments, int skin_every = 0);
    /// Reads counters and particles after a frame.
    void sample(const Registry& registry);
    /// Per garment, over `frames` frames sampled so far.
    [[nodiscard]] std::vector<GarmentStats> result(const Registry& registry) const;
    [[nodiscard]] std::uint64_t frames() const noexcept { return m_frames; }
    /// The 99th percentile of spring strain in the last frame sampled, the largest over the
    /// garments (0.05 = 5 %); 0 before the first frame.
    [[nodiscard]] double latest_strain_p99() const noexcept { return m_latest_strain_p99; }

private:
    struct Track {
        Entity entity;
        GarmentStats worst;
        std::shared_ptr<StrainHistogram> strains = std::make_shared<StrainHistogram>();
        std::uint64_t tests_at_start = 0, resets_at_start = 0, budget_hits_at_start = 0, line_steps_at_start = 0;
        std::uint64_t substeps_sum = 0;
        std::vector<std::uint64_t> skin_depths;  ///< Histogram of depths behind the skin (skin_bin_m bins; the last: beyond).
        std::uint64_t skin_free = 0, skin_behind = 0;
        bool skin_measured = false;
    };
    static constexpr double skin_bin_m = 5e-5;
    static constexpr std::size_t skin_bins = 10000;  ///< Up to 0.5 m.
    std::vector<Track> m_tracks;
    int m_skin_every = 0;
    std::uint64_t m_frames = 0;
    double m_latest_strain_p99 = 0;
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
