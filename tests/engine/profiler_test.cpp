#include "drape/engine/core/profiler.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

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
        EXPECT_EQ(ev["ph"], "X");
        EXPECT_GE(ev["dur"].get<long>(), 0);
        EXPECT_TRUE(ev.contains("ts") && ev.contains("pid") && ev.contains("tid"));
        const std::string name = ev["name"];
        cloth += name == "cloth";
        render += name == "render";
        frames += name == "frame";
    }
    EXPECT_EQ(cloth, 5);
    EXPECT_EQ(render, 5);
    EXPECT_EQ(frames, 5);
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
