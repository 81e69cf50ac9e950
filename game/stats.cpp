#include "game/stats.hpp"

#include <cmath>
#include <fstream>

#include <nlohmann/json.hpp>

#include "components/garment.hpp"

namespace drape {

GarmentWatch::GarmentWatch(const Registry& registry, std::vector<Entity> garments) {
    for (Entity e : garments) {
        const Garment* g = registry.try_get<Garment>(e);
        m_tracks.push_back(Track{.entity = e, .tests_at_start = g ? g->counters.collision_tests : 0});
    }
}

void GarmentWatch::sample(const Registry& registry) {
    ++m_frames;
    for (Track& t : m_tracks) {
        const Garment* g = registry.try_get<Garment>(t.entity);
        if (g == nullptr) continue;
        const GarmentCounters& c = g->counters;
        if (std::isfinite(c.max_strain)) t.max_strain = std::max(t.max_strain, double(c.max_strain));
        if (std::isfinite(c.max_penetration_m)) t.max_penetration_m = std::max(t.max_penetration_m, double(c.max_penetration_m));
        for (Eigen::Index i = 0; i < g->state.x.cols(); ++i)
            if (!g->state.x.col(i).allFinite() || (i < g->state.v.cols() && !g->state.v.col(i).allFinite())) ++t.nonfinite_seen;
    }
}

std::vector<GarmentStats> GarmentWatch::result(const Registry& registry) const {
    std::vector<GarmentStats> out;
    for (const Track& t : m_tracks) {
        GarmentStats s;
        s.max_strain = t.max_strain;
        s.max_penetration_m = t.max_penetration_m;
        s.nonfinite = t.nonfinite_seen;
        if (const Garment* g = registry.try_get<Garment>(t.entity)) {
            s.particles = static_cast<std::uint64_t>(g->state.x.cols());
            s.nonfinite += g->counters.non_finite_values;
            if (m_frames > 0)
                s.collision_tests_per_frame = double(g->counters.collision_tests - t.tests_at_start) / double(m_frames);
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
    Json garments = Json::array();
    for (const GarmentStats& g : stats.garments)
        garments.push_back({{"particles", g.particles},
                            {"max_strain", number(g.max_strain)},
                            {"max_penetration_m", number(g.max_penetration_m)},
                            {"nonfinite", g.nonfinite},
                            {"collision_tests_per_frame", number(g.collision_tests_per_frame)}});
    Json j = {{"frames", stats.frames}, {"sim_dt_s", number(stats.sim_dt_s)}, {"systems", std::move(systems)},
              {"garments", std::move(garments)}};
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
