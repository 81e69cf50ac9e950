#include "drape/engine/core/scheduler.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace drape {

const char* phase_name(Phase p) noexcept {
    switch (p) {
        case Phase::input: return "input";
        case Phase::animation: return "animation";
        case Phase::skinning: return "skinning";
        case Phase::simulation: return "simulation";
        case Phase::render: return "render";
    }
    return "?";
}

Result<void> validate(const SchedulerSettings& s) {
    if (!std::isfinite(s.fixed_dt_s) || s.fixed_dt_s <= 0 || s.fixed_dt_s > 1.0)
        return fail("solver.fixed_dt_s: must be a finite number in (0, 1] seconds, got " + std::to_string(s.fixed_dt_s));
    if (s.max_steps_per_frame < 1 || s.max_steps_per_frame > 1000)
        return fail("solver.max_steps_per_frame: must be in [1, 1000], got " + std::to_string(s.max_steps_per_frame));
    if (!std::isfinite(s.time_scale) || s.time_scale < 0 || s.time_scale > 1000)
        return fail("solver.time_scale: must be a finite number in [0, 1000], got " + std::to_string(s.time_scale));
    return {};
}

Scheduler::Scheduler(SchedulerSettings settings) : m_settings(settings) {}

Result<Scheduler> Scheduler::create(SchedulerSettings settings) {
    if (auto ok = validate(settings); !ok) return std::unexpected(ok.error());
    return Scheduler(settings);
}

Result<void> Scheduler::set_time_scale(double scale) {
    SchedulerSettings s = m_settings;
    s.time_scale = scale;
    if (auto ok = validate(s); !ok) return ok;
    m_settings = s;
    return {};
}

std::uint32_t Scheduler::add(System system) {
    const std::uint32_t slot = m_profiler.add_slot(system.name);
    m_phases[static_cast<std::size_t>(system.phase)].push_back(Entry{std::move(system), slot});
    return slot;
}

bool Scheduler::present(const Registry& registry, const System& system) {
    auto has_all = [&](const std::vector<ComponentId>& ids) {
        return std::all_of(ids.begin(), ids.end(), [&](ComponentId id) { return registry.count(id) > 0; });
    };
    return has_all(system.reads) && has_all(system.writes);
}

void Scheduler::run_phase(Registry& registry, Phase phase, const FrameContext& context) {
    FrameContext ctx = context;
    ctx.profiler = &m_profiler;
    for (Entry& entry : m_phases[static_cast<std::size_t>(phase)]) {
        if (!present(registry, entry.system)) {
            m_profiler.record_skip(entry.slot);
            continue;
        }
        ProfileScope scope(m_profiler, entry.slot);
        entry.system.run(registry, ctx);
    }
}

Result<FrameReport> Scheduler::tick(Registry& registry, double frame_dt_s) {
    if (!std::isfinite(frame_dt_s) || frame_dt_s < 0)
        return fail("frame time: must be a finite number >= 0 seconds, got " + std::to_string(frame_dt_s));

    m_profiler.begin_frame();
    FrameContext context;
    context.frame = m_frame;
    context.frame_dt_s = frame_dt_s;
    context.fixed_dt_s = m_settings.fixed_dt_s;
    context.time_s = m_time_s;

    run_phase(registry, Phase::input, context);

    // Fixed steps from the accumulator, capped; the excess is dropped (see header).
    m_accumulator_s += frame_dt_s * m_settings.time_scale;
    const double step_s = m_settings.fixed_dt_s;
    int steps = static_cast<int>(std::floor(m_accumulator_s / step_s + 1e-9));
    FrameReport report;
    if (steps > m_settings.max_steps_per_frame) {
        steps = m_settings.max_steps_per_frame;
        report.dropped_s = m_accumulator_s - steps * step_s;
        m_accumulator_s = 0;
        m_total_dropped_s += report.dropped_s;
    } else {
        m_accumulator_s = std::max(0.0, m_accumulator_s - steps * step_s);
    }
    report.steps = steps;
    context.steps = steps;

    for (int step = 0; step < steps; ++step) {
        context.step = step;
        context.time_s = m_time_s;
        run_phase(registry, Phase::animation, context);
        run_phase(registry, Phase::skinning, context);
        run_phase(registry, Phase::simulation, context);
        m_time_s += step_s;
    }

    context.time_s = m_time_s;
    run_phase(registry, Phase::render, context);
    m_profiler.end_frame();
    ++m_frame;
    return report;
}

std::vector<std::string> Scheduler::system_names(Phase phase) const {
    std::vector<std::string> names;
    for (const Entry& e : m_phases[static_cast<std::size_t>(phase)]) names.push_back(e.system.name);
    return names;
}

}  // namespace drape
