#include "drape/game/frame_hud.hpp"

#include <algorithm>
#include <cstdio>

#include "drape/components/garment.hpp"
#include "drape/game/world.hpp"

namespace drape {

namespace {

constexpr double window_ms = 1000;
constexpr std::size_t max_frames = 2000;

/// The q-th quantile (0..1) of the values, nearest rank; 0 for none.
double quantile(std::vector<double>& values, double q) {
    if (values.empty()) return 0;
    const auto k = std::min(values.size() - 1, std::size_t(q * double(values.size() - 1) + 0.5));
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
    return values[k];
}

std::string format(const char* pattern, auto... values) {
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, pattern, values...);
    return buffer;
}

}  // namespace

void FrameHud::record(const World& world, double wall_ms) {
    const FrameProfiler& profiler = world.scheduler.profiler();
    const std::size_t slots = profiler.slot_count();
    if (m_names.size() != slots) {  // slots are only ever added
        m_names.clear();
        m_sections.clear();
        for (std::uint32_t i = 0; i < slots; ++i) {
            m_names.push_back(profiler.slot_name(i));
            m_sections.push_back(profiler.slot_parent(i) != FrameProfiler::no_parent);
        }
    }
    Frame frame;
    frame.wall_ms = std::max(0.0, wall_ms);
    frame.system_ms.resize(slots);
    for (std::uint32_t i = 0; i < slots; ++i) frame.system_ms[i] = profiler.last_frame_ms(i);
    m_window_wall_ms += frame.wall_ms;
    m_frames.push_back(std::move(frame));
    while (m_frames.size() > 1 && (m_window_wall_ms - m_frames.front().wall_ms >= window_ms || m_frames.size() > max_frames)) {
        m_window_wall_ms -= m_frames.front().wall_ms;
        m_frames.pop_front();
    }

    m_garments = 0;
    m_particles = 0;
    m_substeps = 0;
    m_budget_hits = 0;
    for (const Entity e : world.garments) {
        const Garment* g = world.registry.try_get<Garment>(e);
        if (g == nullptr) continue;
        ++m_garments;
        m_particles += std::uint64_t(g->state.x.cols());
        m_substeps = std::max(m_substeps, g->counters.substeps);
        m_budget_hits += g->counters.budget_hits;
    }
    m_strain_p99 = world.watch.latest_strain_p99();
}

double FrameHud::fps() const {
    std::size_t timed = 0;
    for (const Frame& f : m_frames) timed += f.wall_ms > 0 ? 1 : 0;
    return m_window_wall_ms > 0 ? 1000.0 * double(timed) / m_window_wall_ms : 0;
}

HudOverlay FrameHud::overlay() const {
    HudOverlay hud;
    std::vector<double> values;
    values.reserve(m_frames.size());
    for (const Frame& f : m_frames)
        if (f.wall_ms > 0) values.push_back(f.wall_ms);
    const double last_wall = m_frames.empty() ? 0 : m_frames.back().wall_ms;
    const double p50_wall = quantile(values, 0.5), p95_wall = quantile(values, 0.95);
    hud.lines.push_back(format("%.0f fps   frame %.1f ms  p50 %.1f  p95 %.1f", fps(), last_wall, p50_wall, p95_wall));
    hud.lines.push_back(format("garments %zu  particles %llu  substeps %d", m_garments,
                               static_cast<unsigned long long>(m_particles), m_substeps));
    hud.lines.push_back(format("strain p99 %.1f %%  budget hits %llu", 100 * m_strain_p99,
                               static_cast<unsigned long long>(m_budget_hits)));
    double largest_p95 = 0;
    for (std::size_t i = 0; i < m_names.size(); ++i) {
        values.clear();
        for (const Frame& f : m_frames) values.push_back(i < f.system_ms.size() ? f.system_ms[i] : 0);
        HudBar bar;
        bar.name = m_names[i];
        bar.section = m_sections[i];
        bar.last_ms = m_frames.empty() ? 0 : values.back();
        bar.p50_ms = quantile(values, 0.5);
        bar.p95_ms = quantile(values, 0.95);
        largest_p95 = std::max(largest_p95, bar.p95_ms);
        hud.bars.push_back(std::move(bar));
    }
    // A full bar is the largest system's 95th percentile rounded up to 1, 2 or 5 times a
    // power of ten: the bars compare the systems (the frame's own time is in the text).
    hud.full_bar_ms = 0.01;
    for (double decade = 0.01; hud.full_bar_ms < largest_p95 && decade < 1e6; decade *= 10)
        for (double step : {1.0, 2.0, 5.0, 10.0})
            if (hud.full_bar_ms < largest_p95) hud.full_bar_ms = step * decade;
    return hud;
}

std::string FrameHud::title() const {
    const double last_wall = m_frames.empty() ? 0 : m_frames.back().wall_ms;
    return format("Drape  %.0f fps  %.1f ms", fps(), last_wall);
}

}  // namespace drape
