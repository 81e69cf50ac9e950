#include "drape/engine/core/profiler.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <algorithm>
#include <fstream>
#include <map>
#include <thread>
#include <vector>

#include <unistd.h>

#include "drape/engine/core/scheduler.hpp"

namespace drape {
namespace {

struct Body {};

TEST(FrameProfiler, ReportsRunsSkipsAndPercentiles) {
    FrameProfiler p;
    const auto slot = p.add_slot("work");
    const auto t0 = FrameProfiler::Clock::now();
    for (int i = 1; i <= 100; ++i) {
        p.begin_frame();
        p.record_run(slot, t0, t0 + std::chrono::microseconds(i * 10));  // 0.01 .. 1.00 ms
        p.end_frame();
    }
    p.record_skip(slot);
    const SystemStats s = p.stats("work");
    EXPECT_EQ(s.runs, 100u);
    EXPECT_EQ(s.skips, 1u);
    EXPECT_NEAR(s.mean_ms, 0.505, 1e-6);
    EXPECT_NEAR(s.p50_ms, 0.51, 0.011);
    EXPECT_NEAR(s.p95_ms, 0.95, 0.011);
    EXPECT_NEAR(s.max_ms, 1.0, 1e-9);
    EXPECT_NE(p.table().find("work"), std::string::npos);
}

// An engine's own profiler sees every system begin and end, in run order, with its name,
// whether or not Drape times the runs; a skipped system is not announced.
TEST(FrameProfiler, HooksSeeEverySystemBeginAndEnd) {
    for (bool timing : {true, false}) {
        Registry r;
        r.emplace<Body>(r.create());
        Scheduler s;
        s.profiler().set_timing(timing);
        std::vector<std::string> seen;
        bool inside = false;
        s.profiler().set_hooks({[&](std::uint32_t, std::string_view name) {
                                    EXPECT_FALSE(inside);
                                    inside = true;
                                    seen.push_back(std::string("+").append(name));
                                },
                                [&](std::uint32_t, std::string_view name) {
                                    EXPECT_TRUE(inside);
                                    inside = false;
                                    seen.push_back(std::string("-").append(name));
                                }});
        s.add({"cloth", Phase::simulation, {}, components<Body>(), {}, [&](Registry&, const FrameContext&) {
                   EXPECT_TRUE(inside);
               }});
        s.add({"render", Phase::render, {}, components<Body>(), {}, [](Registry&, const FrameContext&) {}});
        s.add({"absent", Phase::render, components<int>(), {}, {}, [](Registry&, const FrameContext&) {}});
        ASSERT_TRUE(s.tick(r, 1.0 / 60.0));
        EXPECT_EQ(seen, (std::vector<std::string>{"+cloth", "-cloth", "+render", "-render"})) << "timing " << timing;
    }
}

TEST(FrameProfiler, LastFrameSumsEachSlotsRunsInTheLastWholeFrame) {
    FrameProfiler p;
    const auto system = p.add_slot("system");
    const auto section = p.add_slot("section", system);
    ASSERT_EQ(p.slot_count(), 2u);
    EXPECT_EQ(p.slot_name(section), "section");
    EXPECT_EQ(p.slot_parent(section), system);
    EXPECT_EQ(p.slot_parent(system), FrameProfiler::no_parent);
    const auto t0 = FrameProfiler::Clock::now();
    p.begin_frame();
    p.record_run(system, t0, t0 + std::chrono::milliseconds(5));
    p.end_frame();
    p.begin_frame();  // two fixed steps in this frame
    p.record_run(system, t0, t0 + std::chrono::milliseconds(1));
    p.record_run(system, t0, t0 + std::chrono::milliseconds(2));
    p.record_run(section, t0, t0 + std::chrono::microseconds(500));
    EXPECT_DOUBLE_EQ(p.last_frame_ms(system), 5.0) << "a frame under way is not the last whole one";
    p.end_frame();
    EXPECT_DOUBLE_EQ(p.last_frame_ms(system), 3.0);
    EXPECT_DOUBLE_EQ(p.last_frame_ms(section), 0.5);
    p.begin_frame();
    p.end_frame();
    EXPECT_DOUBLE_EQ(p.last_frame_ms(system), 0.0) << "no run in the last frame";
    p.reset();
    EXPECT_DOUBLE_EQ(p.last_frame_ms(system), 0.0);
}

TEST(FrameProfiler, TraceFileIsChromeTraceJsonWithOneEventPerRun) {
    Registry r;
    r.emplace<Body>(r.create());
    Scheduler s;
    s.add({"cloth", Phase::simulation, {}, components<Body>(), {}, [](Registry&, const FrameContext&) {
               std::this_thread::sleep_for(std::chrono::microseconds(50));
           }});
    s.add({"render", Phase::render, {}, components<Body>(), {}, [](Registry&, const FrameContext&) {}});
    for (int i = 0; i < 5; ++i) ASSERT_TRUE(s.tick(r, 1.0 / 60.0));

    const auto file = std::filesystem::temp_directory_path() / "drape_profiler_test_trace.json";
    ASSERT_TRUE(s.profiler().write_trace(file));
    std::ifstream is(file);
    const nlohmann::json trace = nlohmann::json::parse(is);  // throws (fails) if not JSON
    std::filesystem::remove(file);
    ASSERT_TRUE(trace.contains("traceEvents"));
    int cloth = 0, render = 0, frames = 0;
    for (const auto& ev : trace["traceEvents"]) {
        EXPECT_TRUE(ev.contains("ts") || ev["ph"] == "M");
        EXPECT_TRUE(ev.contains("pid") && ev.contains("tid"));
        if (ev["ph"] == "M") continue;  // metadata: names of the process and its threads
        EXPECT_EQ(ev["ph"], "X");
        EXPECT_GE(ev["dur"].get<double>(), 0);
        const std::string name = ev["name"];
        cloth += name == "cloth";
        render += name == "render";
        frames += name == "frame";
    }
    EXPECT_EQ(cloth, 5);
    EXPECT_EQ(render, 5);
    EXPECT_EQ(frames, 5);
}

// Reads a trace file as JSON.
nlohmann::json read_trace(const FrameProfiler& p) {
    const auto file = std::filesystem::temp_directory_path() / ("drape_profiler_test_trace_" + std::to_string(::getpid()) + ".json");
    EXPECT_TRUE(p.write_trace(file));
    std::ifstream is(file);
    nlohmann::json trace = nlohmann::json::parse(is);
    std::filesystem::remove(file);
    return trace;
}

TEST(FrameProfiler, TraceKeepsTheMostRecentEventsAndCountsTheDropped) {
    FrameProfiler p;
    const auto slot = p.add_slot("work");
    p.set_trace_capacity(16);
    EXPECT_EQ(p.trace_capacity(), 16u);
    const auto t0 = FrameProfiler::Clock::now();
    for (int i = 0; i < 20; ++i) p.record_run(slot, t0 + std::chrono::microseconds(i), t0 + std::chrono::microseconds(i + 1));
    EXPECT_EQ(p.trace_events_recorded(), 20u);
    EXPECT_EQ(p.trace_events_dropped(), 4u);
    EXPECT_EQ(p.stats("work").runs, 20u);  // the statistics keep every run
    const nlohmann::json trace = read_trace(p);
    EXPECT_EQ(trace["otherData"]["recorded_events"], 20);
    EXPECT_EQ(trace["otherData"]["kept_events"], 16);
    EXPECT_EQ(trace["otherData"]["dropped_events"], 4);
    EXPECT_EQ(trace["otherData"]["trace_capacity"], 16);
    std::vector<double> starts;
    for (const auto& ev : trace["traceEvents"])
        if (ev["ph"] == "X") starts.push_back(ev["ts"].get<double>());
    ASSERT_EQ(starts.size(), 16u);
    EXPECT_TRUE(std::is_sorted(starts.begin(), starts.end())) << "oldest kept first";
    // Times are microseconds from the trace's origin, in doubles: the difference of two of
    // them is 15 us to their rounding, not to the last bit.
    EXPECT_NEAR(starts.back() - starts.front(), 15.0, 1e-6) << "the last 16 runs, 1 us apart";
    p.reset();
    EXPECT_EQ(p.trace_events_recorded(), 0u);
    EXPECT_EQ(p.trace_events_dropped(), 0u);
}

TEST(FrameProfiler, TraceTimesAreSubMicrosecondAndEveryThreadIsNamed) {
    FrameProfiler p;
    const auto slot = p.add_slot("work");
    const auto t0 = FrameProfiler::Clock::now();
    p.begin_frame();
    p.record_run(slot, t0 + std::chrono::nanoseconds(250), t0 + std::chrono::nanoseconds(1750));  // 1.5 us
    std::thread([&] { p.record_run(slot, t0, t0 + std::chrono::nanoseconds(125)); }).join();
    p.end_frame();
    const nlohmann::json trace = read_trace(p);
    std::map<int, std::string> thread_names;
    std::vector<nlohmann::json> runs;
    for (const auto& ev : trace["traceEvents"]) {
        if (ev["ph"] == "M" && ev["name"] == "thread_name") thread_names[ev["tid"].get<int>()] = ev["args"]["name"];
        if (ev["ph"] == "X" && ev["name"] == "work") runs.push_back(ev);
    }
    ASSERT_EQ(runs.size(), 2u);
    EXPECT_DOUBLE_EQ(runs[0]["dur"].get<double>(), 1.5);
    EXPECT_DOUBLE_EQ(runs[1]["dur"].get<double>(), 0.125);
    EXPECT_NEAR(runs[0]["ts"].get<double>() - runs[1]["ts"].get<double>(), 0.25, 1e-6);
    EXPECT_NE(runs[0]["tid"], runs[1]["tid"]) << "two threads, two tracks";
    EXPECT_EQ(thread_names[runs[0]["tid"].get<int>()], "scheduler");
    EXPECT_EQ(thread_names[runs[1]["tid"].get<int>()], "thread 2");
    EXPECT_EQ(thread_names[1], "frames");
}

TEST(FrameProfiler, TraceToAnUnwritablePathIsAnErrorNamingTheFile) {
    FrameProfiler p;
    auto ok = p.write_trace("/nonexistent-dir/trace.json");
    ASSERT_FALSE(ok);
    EXPECT_NE(ok.error().message.find("/nonexistent-dir/trace.json"), std::string::npos);
}

TEST(FrameProfiler, TimingOffStillCountsRuns) {
    Registry r;
    r.emplace<Body>(r.create());
    Scheduler s;
    s.profiler().set_timing(false);
    s.add({"cloth", Phase::simulation, {}, components<Body>(), {}, [](Registry&, const FrameContext&) {}});
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(s.tick(r, 1.0 / 60.0));
    EXPECT_EQ(s.profiler().stats("cloth").runs, 3u);
    EXPECT_EQ(s.profiler().stats("cloth").total_ms, 0.0);
}

}  // namespace
}  // namespace drape
