// Frame profiler: how much of each frame every system costs.
//
// The scheduler times each system run with a steady clock (an RAII `ProfileScope`) and
// records skips. Per system the profiler keeps totals (runs, skips, sum, max) and a ring
// buffer of recent durations for percentiles; a second ring keeps the most recent trace
// events for Chrome's trace event format (opens in Perfetto or chrome://tracing), counts
// the ones it no longer holds, and records which thread ran each (times in nanoseconds,
// written in microseconds with three decimals).
// Timing is opt-in in the sense of flecs: `set_timing(false)` leaves only the counters,
// and bench/profiler_overhead measures what timing costs.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <thread>
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

    /// Keeps the most recent `events` trace events (at least 16) from now on; forgets the
    /// trace so far. Durations for percentiles keep their own capacity.
    void set_trace_capacity(std::size_t events);
    [[nodiscard]] std::size_t trace_capacity() const noexcept { return m_trace_capacity; }
    /// Trace events recorded since the start (or the last reset), kept or not.
    [[nodiscard]] std::uint64_t trace_events_recorded() const noexcept { return m_events_recorded; }
    /// Of those, the ones the ring no longer holds (the oldest, overwritten).
    [[nodiscard]] std::uint64_t trace_events_dropped() const noexcept { return m_events_recorded - m_events.size(); }

    static constexpr std::uint32_t no_parent = 0xffffffffu;

    /// Registers a named slot (a system, or any timed section) and returns its index. A
    /// section of another slot names it as `parent`: it is listed under it, and a skip of
    /// the parent counts for it too.
    std::uint32_t add_slot(std::string name, std::uint32_t parent = no_parent);

    /// An engine's own profiler (Tracy, a game's): told when each system or timed section
    /// begins and ends, on the thread that runs it, with the slot's name (valid until the
    /// next add_slot). Called whether or not Drape times the run; empty: not called.
    struct Hooks {
        std::function<void(std::uint32_t slot, std::string_view name)> begin;
        std::function<void(std::uint32_t slot, std::string_view name)> end;
    };
    void set_hooks(Hooks hooks) { m_hooks = std::move(hooks); }
    [[nodiscard]] const Hooks& hooks() const noexcept { return m_hooks; }

    [[nodiscard]] bool timing() const noexcept { return m_timing; }
    void set_timing(bool on) noexcept { m_timing = on; }

    void begin_frame() noexcept;
    void end_frame() noexcept;
    void record_run(std::uint32_t slot, Clock::time_point start, Clock::time_point end) noexcept;
    void record_untimed_run(std::uint32_t slot) noexcept { ++m_slots[slot].runs; }
    void record_skip(std::uint32_t slot) noexcept;

    [[nodiscard]] std::uint64_t frames() const noexcept { return m_frames; }
    /// Slots registered, in order; their names, and the slot each is a section of.
    [[nodiscard]] std::size_t slot_count() const noexcept { return m_slots.size(); }
    [[nodiscard]] const std::string& slot_name(std::uint32_t slot) const { return m_slots[slot].name; }
    [[nodiscard]] std::uint32_t slot_parent(std::uint32_t slot) const { return m_slots[slot].parent; }
    /// Time of a slot's runs within the last whole frame (every fixed step of it), ms;
    /// 0 when it did not run or timing is off.
    [[nodiscard]] double last_frame_ms(std::uint32_t slot) const { return m_slots[slot].last_frame_ms; }
    /// Mean wall time of a whole frame (all phases, scheduler overhead included), ms.
    [[nodiscard]] double mean_frame_ms() const noexcept;
    [[nodiscard]] std::vector<SystemStats> stats() const;
    [[nodiscard]] SystemStats stats(std::string_view name) const;

    /// The frame budget table printed at the end of a run.
    [[nodiscard]] std::string table() const;

    /// Writes Chrome trace event JSON ({"traceEvents": [...]}) with one complete ("X")
    /// event per kept system run and frame, times in microseconds to the nanosecond, and
    /// metadata ("M") naming the process and the threads: "frames" for the frames,
    /// "scheduler" for the first thread that ran a system, "thread N" for others.
    /// "otherData" says how many events were recorded, kept and dropped.
    [[nodiscard]] Result<void> write_trace(const std::filesystem::path& file) const;

    /// Forgets all samples (slots stay registered).
    void reset() noexcept;

private:
    struct Slot {
        std::string name;
        std::uint32_t parent = no_parent;
        std::uint64_t runs = 0, skips = 0;
        double total_ms = 0, max_ms = 0;
        double frame_ms = 0;           ///< Runs of the frame under way.
        double last_frame_ms = 0;      ///< Runs of the last whole frame.
        std::vector<float> recent_ms;  ///< Ring buffer.
        std::size_t next = 0;
    };
    struct TraceEvent {
        std::uint32_t slot;    ///< UINT32_MAX = the frame itself.
        std::uint32_t thread;  ///< Index into m_threads.
        std::int64_t start_ns, duration_ns;
    };
    void push_event(std::uint32_t slot, Clock::time_point start, Clock::time_point end) noexcept;
    std::uint32_t thread_index() noexcept;

    std::size_t m_capacity;
    std::size_t m_trace_capacity;
    bool m_timing = true;
    Hooks m_hooks;
    std::vector<Slot> m_slots;
    std::vector<TraceEvent> m_events;  ///< Ring buffer of trace events.
    std::size_t m_next_event = 0;
    std::uint64_t m_events_recorded = 0;
    std::vector<std::thread::id> m_threads;  ///< Threads that recorded an event, in order of their first.
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
        if (const auto& begin = m_profiler.hooks().begin) begin(m_slot, m_profiler.slot_name(m_slot));
        if (m_profiler.timing()) m_start = FrameProfiler::Clock::now();
    }
    ~ProfileScope() {
        if (m_profiler.timing())
            m_profiler.record_run(m_slot, m_start, FrameProfiler::Clock::now());
        else
            m_profiler.record_untimed_run(m_slot);
        if (const auto& end = m_profiler.hooks().end) end(m_slot, m_profiler.slot_name(m_slot));
    }
    ProfileScope(const ProfileScope&) = delete;
    ProfileScope& operator=(const ProfileScope&) = delete;

private:
    FrameProfiler& m_profiler;
    std::uint32_t m_slot;
    FrameProfiler::Clock::time_point m_start{};
};

}  // namespace drape
