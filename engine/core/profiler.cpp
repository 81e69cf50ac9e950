#include "drape/engine/core/profiler.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>

namespace drape {

namespace {
constexpr std::uint32_t frame_slot = std::numeric_limits<std::uint32_t>::max();

double percentile(std::vector<float> values, double q) {
    if (values.empty()) return 0;
    const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5);
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
    return values[k];
}

std::string json_escape(std::string_view s) {
    std::string out;
    for (char c : s) {
        if (c == '"' || c == '\\') { out += '\\'; out += c; }
        else if (static_cast<unsigned char>(c) < 0x20) { char buf[8]; std::snprintf(buf, sizeof buf, "\\u%04x", c); out += buf; }
        else out += c;
    }
    return out;
}
}  // namespace

FrameProfiler::FrameProfiler(std::size_t ring_capacity)
    : m_capacity(std::max<std::size_t>(ring_capacity, 16)), m_trace_capacity(m_capacity) {}

void FrameProfiler::set_trace_capacity(std::size_t events) {
    m_trace_capacity = std::max<std::size_t>(events, 16);
    m_events.clear();
    m_events.shrink_to_fit();
    m_next_event = 0;
    m_events_recorded = 0;
}

std::uint32_t FrameProfiler::add_slot(std::string name, std::uint32_t parent) {
    Slot slot;
    slot.name = std::move(name);
    slot.parent = parent < m_slots.size() ? parent : no_parent;
    slot.recent_ms.reserve(m_capacity);
    m_slots.push_back(std::move(slot));
    return static_cast<std::uint32_t>(m_slots.size() - 1);
}

void FrameProfiler::record_skip(std::uint32_t slot) noexcept {
    ++m_slots[slot].skips;
    for (Slot& s : m_slots)
        if (s.parent == slot) ++s.skips;
}

void FrameProfiler::begin_frame() noexcept {
    for (Slot& s : m_slots) s.frame_ms = 0;
    if (m_timing) m_frame_start = Clock::now();
}

void FrameProfiler::end_frame() noexcept {
    ++m_frames;
    for (Slot& s : m_slots) s.last_frame_ms = s.frame_ms;
    if (!m_timing) return;
    const auto end = Clock::now();
    m_frame_total_ms += std::chrono::duration<double, std::milli>(end - m_frame_start).count();
    push_event(frame_slot, m_frame_start, end);
}

void FrameProfiler::record_run(std::uint32_t slot, Clock::time_point start, Clock::time_point end) noexcept {
    Slot& s = m_slots[slot];
    const double ms = std::chrono::duration<double, std::milli>(end - start).count();
    ++s.runs;
    s.total_ms += ms;
    s.frame_ms += ms;
    s.max_ms = std::max(s.max_ms, ms);
    if (s.recent_ms.size() < m_capacity) s.recent_ms.push_back(static_cast<float>(ms));
    else s.recent_ms[s.next] = static_cast<float>(ms);
    s.next = (s.next + 1) % m_capacity;
    push_event(slot, start, end);
}

std::uint32_t FrameProfiler::thread_index() noexcept {
    const std::thread::id self = std::this_thread::get_id();
    for (std::size_t i = 0; i < m_threads.size(); ++i)
        if (m_threads[i] == self) return static_cast<std::uint32_t>(i);
    try {
        m_threads.push_back(self);
    } catch (...) {
        return 0;  // out of memory: counted with the first thread
    }
    return static_cast<std::uint32_t>(m_threads.size() - 1);
}

void FrameProfiler::push_event(std::uint32_t slot, Clock::time_point start, Clock::time_point end) noexcept {
    const TraceEvent ev{slot, slot == frame_slot ? 0u : thread_index(),
                        std::chrono::duration_cast<std::chrono::nanoseconds>(start - m_origin).count(),
                        std::chrono::duration_cast<std::chrono::nanoseconds>(end - start).count()};
    ++m_events_recorded;
    if (m_events.size() < m_trace_capacity) {
        try {
            m_events.push_back(ev);
        } catch (...) {
            return;  // out of memory: the event is dropped, and counted so
        }
    } else {
        m_events[m_next_event] = ev;
    }
    m_next_event = (m_next_event + 1) % m_trace_capacity;
}

double FrameProfiler::mean_frame_ms() const noexcept {
    return m_frames ? m_frame_total_ms / static_cast<double>(m_frames) : 0;
}

std::vector<SystemStats> FrameProfiler::stats() const {
    std::vector<SystemStats> out;
    out.reserve(m_slots.size());
    for (const Slot& s : m_slots) {
        SystemStats st;
        st.name = s.name;
        if (s.parent != no_parent) st.parent = m_slots[s.parent].name;
        st.runs = s.runs;
        st.skips = s.skips;
        st.total_ms = s.total_ms;
        st.max_ms = s.max_ms;
        st.mean_ms = s.recent_ms.empty() ? 0 : s.total_ms / static_cast<double>(s.runs);
        st.p50_ms = percentile(s.recent_ms, 0.50);
        st.p95_ms = percentile(s.recent_ms, 0.95);
        st.share = m_frame_total_ms > 0 ? s.total_ms / m_frame_total_ms : 0;
        out.push_back(std::move(st));
    }
    return out;
}

SystemStats FrameProfiler::stats(std::string_view name) const {
    for (SystemStats& s : stats())
        if (s.name == name) return s;
    SystemStats none;
    none.name = std::string(name);
    return none;
}

std::string FrameProfiler::table() const {
    std::string out;
    char line[256];
    std::snprintf(line, sizeof line, "Frame budget over %llu frames (mean frame %.3f ms)\n",
                  static_cast<unsigned long long>(m_frames), mean_frame_ms());
    out += line;
    std::snprintf(line, sizeof line, "%-28s %8s %8s %9s %9s %9s %9s %7s\n", "system", "runs", "skips",
                  "mean ms", "p50 ms", "p95 ms", "max ms", "share");
    out += line;
    for (const SystemStats& s : stats()) {
        const std::string name = s.parent.empty() ? s.name : "  " + s.name;  // a section, under its system
        std::snprintf(line, sizeof line, "%-28s %8llu %8llu %9.4f %9.4f %9.4f %9.4f %6.1f%%\n", name.c_str(),
                      static_cast<unsigned long long>(s.runs), static_cast<unsigned long long>(s.skips), s.mean_ms,
                      s.p50_ms, s.p95_ms, s.max_ms, 100.0 * s.share);
        out += line;
    }
    return out;
}

Result<void> FrameProfiler::write_trace(const std::filesystem::path& file) const {
    std::ofstream os(file, std::ios::binary | std::ios::trunc);
    if (!os) return fail(file.string() + ": cannot open the trace file for writing");
    const std::size_t n = m_events.size();
    os << "{\"displayTimeUnit\":\"ms\",\"otherData\":{\"recorded_events\":" << m_events_recorded
       << ",\"kept_events\":" << n << ",\"dropped_events\":" << trace_events_dropped()
       << ",\"trace_capacity\":" << m_trace_capacity << "},\"traceEvents\":[";
    // Tracks: tid 1 the frames, tid 2 + i the i-th thread that ran a system.
    auto name_thread = [&](int tid, const std::string& name) {
        os << ",\n{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":" << tid << ",\"args\":{\"name\":\""
           << json_escape(name) << "\"}},\n{\"name\":\"thread_sort_index\",\"ph\":\"M\",\"pid\":1,\"tid\":" << tid
           << ",\"args\":{\"sort_index\":" << tid << "}}";
    };
    os << "\n{\"name\":\"process_name\",\"ph\":\"M\",\"pid\":1,\"tid\":0,\"args\":{\"name\":\"drape\"}}";
    name_thread(1, "frames");
    for (std::size_t i = 0; i < m_threads.size(); ++i) name_thread(static_cast<int>(i) + 2, i == 0 ? "scheduler" : "thread " + std::to_string(i + 1));
    // Oldest first: the ring's order starts at m_next_event once it has wrapped.
    const std::size_t first = n < m_trace_capacity ? 0 : m_next_event;
    char times[96];
    for (std::size_t k = 0; k < n; ++k) {
        const TraceEvent& ev = m_events[(first + k) % n];
        const bool is_frame = ev.slot == frame_slot;
        std::snprintf(times, sizeof times, "\"ts\":%.3f,\"dur\":%.3f", static_cast<double>(ev.start_ns) / 1000.0,
                      static_cast<double>(ev.duration_ns) / 1000.0);
        os << ",\n{\"name\":\"" << (is_frame ? std::string("frame") : json_escape(m_slots[ev.slot].name))
           << "\",\"cat\":\"" << (is_frame ? "frame" : "system") << "\",\"ph\":\"X\"," << times
           << ",\"pid\":1,\"tid\":" << (is_frame ? 1 : static_cast<int>(ev.thread) + 2) << "}";
    }
    os << "\n]}\n";
    if (!os) return fail(file.string() + ": write failed");
    return {};
}

void FrameProfiler::reset() noexcept {
    for (Slot& s : m_slots) {
        s.runs = s.skips = 0;
        s.total_ms = s.max_ms = 0;
        s.frame_ms = s.last_frame_ms = 0;
        s.recent_ms.clear();
        s.next = 0;
    }
    m_events.clear();
    m_next_event = 0;
    m_events_recorded = 0;
    m_frames = 0;
    m_frame_total_ms = 0;
}

}  // namespace drape
