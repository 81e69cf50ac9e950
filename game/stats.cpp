#include "drape/game/stats.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/game/skin_penetration.hpp"
#include "drape/systems/cloth/body.hpp"

namespace drape {

GarmentWatch::GarmentWatch(const Registry& registry, std::vector<Entity> garments, int skin_every)
    : m_skin_every(std::max(0, skin_every)) {
    for (Entity e : garments) {
        const Garment* g = registry.try_get<Garment>(e);
        Track t;
        t.entity = e;
        t.tests_at_start = g ? g->counters.collision_tests : 0;
        t.line_steps_at_start = g ? g->counters.line_steps : 0;
        t.resets_at_start = g ? g->counters.resets : 0;
        t.budget_hits_at_start = g ? g->counters.budget_hits : 0;
        if (m_skin_every > 0) t.skin_depths.assign(skin_bins, 0);
        m_tracks.push_back(std::move(t));
    }
}

namespace {

// Where the spring of q.strain_max lies, with its nearest ellipsoid's body region.
WorstSpring worst_spring(const Registry& registry, const Garment& g, const GarmentQuality& q, std::uint64_t frame) {
    std::vector<EllipsoidFrame> frames;
    update_frames(registry, g.body, frames, 1);
    const SpringPlace place = place_spring(g, frames, q.worst_a, q.worst_b);
    WorstSpring w{.seen = true, .frame = frame, .weft = place.weft, .line = place.line, .row = place.row, .rows = place.rows,
                  .straddles = place.straddles};
    if (place.collider >= 0) {
        w.part_thickness_m = place.thickness_m;
        if (const auto* c = registry.try_get<EllipsoidCollider>(g.body.colliders[static_cast<std::size_t>(place.collider)]))
            w.body_part = body_region_name(c->region);
    }
    return w;
}

// The largest speed a free particle's stored velocity gives it (NaN when one is not finite).
double fastest_free_particle(const Garment& g) {
    double fastest = 0;
    const Eigen::Index n = std::min(g.state.v.cols(), g.state.inv_mass.size());
    for (Eigen::Index p = 0; p < n; ++p) {
        if (g.state.inv_mass[p] == 0) continue;
        const double speed = g.state.v.col(p).norm();
        if (!(speed <= fastest)) fastest = speed;  // a NaN is kept
        if (std::isnan(fastest)) break;
    }
    return fastest;
}

}  // namespace

void GarmentWatch::sample(const Registry& registry) {
    ++m_frames;
    // The worst so far; a NaN stays (it is written as null: a bug to report).
    auto worse = [](double& worst, double value) {
        if (!std::isnan(worst) && (std::isnan(value) || value > worst)) worst = value;
    };
    m_latest_strain_p99 = 0;
    for (Track& t : m_tracks) {
        const Garment* g = registry.try_get<Garment>(t.entity);
        if (g == nullptr) continue;
        const GarmentQuality q = measure_garment(registry, *g, t.strains.get());
        m_latest_strain_p99 = std::max(m_latest_strain_p99, double(q.strain_p99));
        GarmentStats& w = t.worst;
        if (q.springs > 0 && (!w.worst_spring.seen || q.strain_max > w.strain_max))
            w.worst_spring = worst_spring(registry, *g, q, m_frames);
        worse(w.strain_max, q.strain_max);
        worse(w.pinned_strain_max, q.pinned_strain_max);
        worse(w.penetration_after_frame_m, q.penetration_m);
        worse(w.within_give_m, q.within_give_m);
        worse(w.pins_inside_m, q.pins_inside_m);
        worse(w.below_ground_m, q.below_ground_m);
        worse(w.rise_above_pins_m, q.rise_above_pins_m);
        worse(w.speed_max_m_s, fastest_free_particle(*g));
        if (std::isnan(q.compression_min) || q.compression_min < w.compression_min) w.compression_min = q.compression_min;
        w.repair_rounds_max = std::max(w.repair_rounds_max, g->counters.frame_repair_rounds);
        w.substeps_max = std::max(w.substeps_max, g->counters.substeps);
        t.substeps_sum += static_cast<std::uint64_t>(std::max(g->counters.substeps, 0));
        worse(w.penetration_before_response_m, g->counters.max_penetration_m);
        w.nonfinite += q.nonfinite;
        if (m_skin_every > 0 && (m_frames - 1) % static_cast<std::uint64_t>(m_skin_every) == 0) {
            const SkinDepths d = skin_depths(registry, *g);
            t.skin_measured = t.skin_measured || d.measured;
            t.skin_free += d.free;
            t.skin_behind += d.behind_m.size();
            for (const double depth : d.behind_m) {
                worse(w.skin_penetration_max_m, depth);
                ++t.skin_depths[std::min(skin_bins - 1, static_cast<std::size_t>(depth / skin_bin_m))];
            }
        }
    }
}

std::vector<GarmentStats> GarmentWatch::result(const Registry& registry) const {
    std::vector<GarmentStats> out;
    for (const Track& t : m_tracks) {
        GarmentStats s = t.worst;
        s.strain_p99 = t.strains->percentile(0.99);
        s.skin_measured = t.skin_measured;
        if (t.skin_measured && t.skin_free > 0) {
            s.skin_penetration_share = double(t.skin_behind) / double(t.skin_free);
            // Upper edge of the bin that holds the 99th percentile of the depths.
            const auto rank = static_cast<std::uint64_t>(std::ceil(0.99 * double(t.skin_behind)));
            std::uint64_t seen = 0;
            for (std::size_t b = 0; b < t.skin_depths.size() && t.skin_behind > 0; ++b) {
                seen += t.skin_depths[b];
                if (seen >= rank) {
                    s.skin_penetration_p99_m = std::min(double(b + 1) * skin_bin_m, s.skin_penetration_max_m);
                    break;
                }
            }
        }
        if (const Garment* g = registry.try_get<Garment>(t.entity)) {
            s.particles = static_cast<std::uint64_t>(g->state.x.cols());
            s.nonfinite += g->counters.non_finite_values;
            s.resets = g->counters.resets - t.resets_at_start;
            s.budget_hits = g->counters.budget_hits - t.budget_hits_at_start;
            if (m_frames > 0) {
                s.collision_tests_per_frame = double(g->counters.collision_tests - t.tests_at_start) / double(m_frames);
                s.line_steps_per_frame = double(g->counters.line_steps - t.line_steps_at_start) / double(m_frames);
                s.substeps_mean = double(t.substeps_sum) / double(m_frames);
            }
        }
        out.push_back(s);
    }
    return out;
}

RunStats make_run_stats(const FrameProfiler& profiler, double sim_dt_s, const GarmentWatch& watch, const Registry& registry) {
    RunStats r;
    r.frames = profiler.frames();
    r.sim_dt_s = sim_dt_s;
    r.systems = profiler.stats();
    r.garments = watch.result(registry);
    return r;
}

nlohmann::json worst_spring_json(const WorstSpring& w) {
    if (!w.seen) return nullptr;
    return {{"frame", w.frame},
            {"spring", w.weft ? "weft" : "warp"},
            {"line", w.line},
            {"row", w.row},
            {"rows", w.rows},
            {"body_part", w.body_part.empty() ? nlohmann::json(nullptr) : nlohmann::json(w.body_part)},
            {"part_thickness_m", w.body_part.empty() ? nlohmann::json(nullptr) : nlohmann::json(w.part_thickness_m)},
            {"straddles", w.straddles}};
}

std::string stats_json(const RunStats& stats) {
    using Json = nlohmann::ordered_json;
    // JSON has no NaN or infinity: a non-finite figure is written as null (and is a bug to report).
    auto number = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
    Json systems = Json::object();
    for (const SystemStats& s : stats.systems)
        systems[s.name] = {{"runs", s.runs},
                           {"skips", s.skips},
                           {"mean_ms", number(s.mean_ms)},
                           {"p50_ms", number(s.p50_ms)},
                           {"p95_ms", number(s.p95_ms)},
                           {"max_ms", number(s.max_ms)}};
    Json characters = Json::array();
    for (const CharacterStats& c : stats.characters)
        characters.push_back({{"file", c.file}, {"clip", c.clip}, {"height_m", number(c.height_m)}});
    Json garments = Json::array();
    for (const GarmentStats& g : stats.garments)
        garments.push_back({{"particles", g.particles},
                            {"strain",
                             {{"max", number(g.strain_max)},
                              {"p99", number(g.strain_p99)},
                              {"pinned_max", number(g.pinned_strain_max)},
                              {"worst", Json(worst_spring_json(g.worst_spring))}}},
                            {"compression_min", number(g.compression_min)},
                            {"penetration_m",
                             {{"after_frame_max", number(g.penetration_after_frame_m)},
                              {"before_response_max", number(g.penetration_before_response_m)},
                              {"within_give_max", number(g.within_give_m)},
                              {"below_ground_max", number(g.below_ground_m)}}},
                            {"skin_penetration_m",
                             g.skin_measured ? Json{{"p99", number(g.skin_penetration_p99_m)},
                                                    {"max", number(g.skin_penetration_max_m)},
                                                    {"share", number(g.skin_penetration_share)}}
                                             : Json{{"p99", nullptr}, {"max", nullptr}, {"share", nullptr}}},
                            {"pins_inside_m", number(g.pins_inside_m)},
                            {"rise_above_pins_m", number(g.rise_above_pins_m)},
                            {"speed_max_m_s", number(g.speed_max_m_s)},
                            {"nonfinite", g.nonfinite},
                            {"resets", g.resets},
                            {"collision_tests_per_frame", number(g.collision_tests_per_frame)},
                            {"line_steps_per_frame", number(g.line_steps_per_frame)},
                            {"repair_rounds_max", g.repair_rounds_max},
                            {"budget_hits", g.budget_hits},
                            {"substeps_mean", number(g.substeps_mean)},
                            {"substeps_max", g.substeps_max},
                            {"max_strain", number(g.strain_max)},
                            {"max_penetration_m", number(g.penetration_before_response_m)}});
    Json j = {{"frames", stats.frames},          {"sim_dt_s", number(stats.sim_dt_s)}, {"characters", std::move(characters)},
              {"systems", std::move(systems)},   {"garments", std::move(garments)}};
    return j.dump(2) + "\n";
}

Result<void> write_file_atomically(const std::filesystem::path& file, std::string_view text) {
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec)) return fail(file.string() + ": is a folder");
    const std::filesystem::path folder = file.parent_path();
    if (!folder.empty() && !std::filesystem::is_directory(folder, ec))
        return fail(file.string() + ": folder " + folder.string() + " does not exist");
    std::filesystem::path temporary = file;
    temporary += ".partial";
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out) return fail(file.string() + ": cannot open for writing");
        out.write(text.data(), static_cast<std::streamsize>(text.size()));
        out.close();
        if (!out) {
            std::filesystem::remove(temporary, ec);
            return fail(file.string() + ": write error (disk full?)");
        }
    }
    std::filesystem::rename(temporary, file, ec);
    if (ec) {
        const std::string why = ec.message();
        std::filesystem::remove(temporary, ec);
        return fail(file.string() + ": cannot write: " + why);
    }
    return {};
}

Result<void> write_stats(const RunStats& stats, const std::filesystem::path& file) {
    return write_file_atomically(file, stats_json(stats));
}

}  // namespace drape
