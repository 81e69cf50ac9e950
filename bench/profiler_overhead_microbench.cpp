// What the frame profiler's timing costs: the same scheduled frame with timing on and off.
// Run: build/bench/drape_microbench --benchmark_filter=Profiler --benchmark_repetitions=5
#include <benchmark/benchmark.h>

#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"

namespace {

struct Counter {
    long value = 0;
};

void scheduled_frame(benchmark::State& state) {
    const bool timing = state.range(0) != 0;
    const int systems = static_cast<int>(state.range(1));
    drape::Registry registry;
    registry.emplace<Counter>(registry.create());
    drape::Scheduler scheduler;
    scheduler.profiler().set_timing(timing);
    for (int i = 0; i < systems; ++i)
        scheduler.add({"system " + std::to_string(i), drape::Phase::simulation, {}, drape::components<Counter>(), {},
                       [](drape::Registry& r, const drape::FrameContext&) {
                           r.view<Counter>().each([](drape::Entity, Counter& c) { ++c.value; });
                       }});
    for (auto _ : state) {
        auto report = scheduler.tick(registry, 1.0 / 60.0);
        benchmark::DoNotOptimize(report);
    }
    state.counters["ns_per_system_run"] = benchmark::Counter(
        static_cast<double>(state.iterations()) * systems, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(scheduled_frame)->Name("Profiler/timing_off")->Args({0, 8})->Args({0, 32});
BENCHMARK(scheduled_frame)->Name("Profiler/timing_on")->Args({1, 8})->Args({1, 32});
