// Frame profiler: how much of each frame every system costs.
//
// The scheduler times each system run with a steady clock (an RAII `ProfileScope`) and
// records skips. Per system the profiler keeps totals (runs, skips, sum, max) and a ring
// buffer of recent durations for percentiles; a second ring keeps trace events for
// Chrome's trace event format (opens in Perfetto or chrome://tracing).
// Timing is opt-in in the sense of flecs: `set_timing(false)` leaves only the counters,
// and bench/profiler_overhead measures what timing costs.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "drape/engine/core/error.hpp"

namespace drape {

/// Summary of one system (or timed section of a system) over a run.
struct SystemStats {
    std::string name;
    std::string parent;  ///< The slot this one is a section of (empty: a system of its own).
    std::uint64_t runs = 0;
    std::uint64_t skips = 0;
    double mean_ms = 0;
    double p50_ms = 0;   ///< Over the most recent runs kept in the ring buffer.
    double p95_ms = 0;
    double max_ms = 0;
    double total_ms = 0;
    double share = 0;    ///< This system's time / the time of all frames, 0..1.
};

class FrameProfiler {
public:
    using Clock = std::chrono::steady_clock;

    /// `ring_capacity`: durations kept per system for percentiles, and trace events kept.
    explicit FrameProfiler(std::size_t ring_capacity = 1 << 14);

    static constexpr std::uint32_t no_parent = 0xffffffffu;

    /// Registers a named slot (a system, or any timed section) and returns its index. A
    /// section of another slot names it as `parent`: it is listed under it, and a skip of
    /// the parent counts for it too.
    std::uint32_t add_slot(std::string name, std::uint32_t parent = no_parent);

    [[nodiscard]] bool timing() const noexcept { return m_timing; }
    void set_timing(bool on) noexcept { m_timing = on; }

    void begin_frame() noexcept;
    void end_frame() noexcept;
    void record_run(std::uint32_t slot, Clock::time_point start, Clock::time_point end) noexcept;
    void record_untimed_run(std::uint32_t slot) noexcept { ++m_slots[slot].runs; }
    void record_skip(std::uint32_t slot) noexcept;

    [[nodiscard]] std::uint64_t frames() const noexcept { return m_frames; }
    /// Mean wall time of a whole frame (all phases, scheduler overhead included), ms.
    [[nodiscard]] double mean_frame_ms() const noexcept;
    [[nodiscard]] std::vector<SystemStats> stats() const;
    [[nodiscard]] SystemStats stats(std::string_view name) const;

    /// The frame budget table printed at the end of a run.
    [[nodiscard]] std::string table() const;

    /// Writes Chrome trace event JSON ({"traceEvents": [...]}) with one complete ("X")
    /// event per recorded system run and per frame.
    [[nodiscard]] Result<void> write_trace(const std::filesystem::path& file) const;

    /// Forgets all samples (slots stay registered).
    void reset() noexcept;

private:
    struct Slot {
        std::string name;
        std::uint32_t parent = no_parent;
        std::uint64_t runs = 0, skips = 0;
        double total_ms = 0, max_ms = 0;
        std::vector<float> recent_ms;  ///< Ring buffer.
        std::size_t next = 0;
    };
    struct TraceEvent {
        std::uint32_t slot;  ///< UINT32_MAX = the frame itself.
        std::int64_t start_us, duration_us;
    };
    void push_event(std::uint32_t slot, Clock::time_point start, Clock::time_point end) noexcept;

    std::size_t m_capacity;
    bool m_timing = true;
    std::vector<Slot> m_slots;
    std::vector<TraceEvent> m_events;  ///< Ring buffer of trace events.
    std::size_t m_next_event = 0;
    std::uint64_t m_frames = 0;
    double m_frame_total_ms = 0;
    Clock::time_point m_origin = Clock::now();
    Clock::time_point m_frame_start{};
};

/// Times one section into a profiler slot; does nothing when timing is off.
class ProfileScope {
public:
    ProfileScope(FrameProfiler& profiler, std::uint32_t slot) noexcept
        : m_profiler(profiler), m_slot(slot) {
        if (m_profiler.timing()) m_start = FrameProfiler::Clock::now();
    }
    ~ProfileScope() {
        if (m_profiler.timing())
            m_profiler.record_run(m_slot, m_start, FrameProfiler::Clock::now());
        else
            m_profiler.record_untimed_run(m_slot);
    }
    ProfileScope(const ProfileScope&) = delete;
    ProfileScope& operator=(const ProfileScope&) = delete;

private:
    FrameProfiler& m_profiler;
    std::uint32_t m_slot;
    FrameProfiler::Clock::time_point m_start{};
};

}  // namespace drape
