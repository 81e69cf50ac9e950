#include "drape/engine/core/scheduler.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace drape {
namespace {

struct Body { float x = 0; };
struct Cloth { float y = 0; };
struct Absent {};

System make_system(std::string name, Phase phase, std::vector<std::string>* log,
                   std::vector<ComponentId> writes = components<Body>()) {
    return System{name, phase, {}, std::move(writes), {},
                  [name, log](Registry&, const FrameContext&) { log->push_back(name); }};
}

TEST(Scheduler, PhasesRunInFixedOrderWhateverTheOrderOfAdding) {
    Registry r;
    r.emplace<Body>(r.create());
    std::vector<std::string> log;
    Scheduler s;
    s.add(make_system("render", Phase::render, &log));
    s.add(make_system("sim", Phase::simulation, &log));
    s.add(make_system("skin", Phase::skinning, &log));
    s.add(make_system("anim", Phase::animation, &log));
    s.add(make_system("input", Phase::input, &log));
    s.add(make_system("sim2", Phase::simulation, &log));
    ASSERT_TRUE(s.tick(r, 1.0 / 60.0));
    EXPECT_EQ(log, (std::vector<std::string>{"input", "anim", "skin", "sim", "sim2", "render"}));
}

TEST(Scheduler, SystemWhoseComponentsAreAbsentIsSkippedAndCounted) {
    Registry r;
    r.emplace<Body>(r.create());
    std::vector<std::string> log;
    Scheduler s;
    s.add(make_system("present", Phase::simulation, &log));
    s.add(make_system("absent", Phase::simulation, &log, components<Body, Absent>()));
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(s.tick(r, 1.0 / 60.0));
    EXPECT_EQ(log, (std::vector<std::string>{"present", "present", "present"}));
    EXPECT_EQ(s.profiler().stats("absent").skips, 3u);
    EXPECT_EQ(s.profiler().stats("absent").runs, 0u);
    EXPECT_EQ(s.profiler().stats("present").runs, 3u);

    // Once the component appears, the system runs.
    r.emplace<Absent>(r.create());
    ASSERT_TRUE(s.tick(r, 1.0 / 60.0));
    EXPECT_EQ(s.profiler().stats("absent").runs, 1u);
}

TEST(Scheduler, OptionalReadsDoNotGate) {
    Registry r;
    r.emplace<Body>(r.create());
    int runs = 0;
    Scheduler s;
    s.add({"render", Phase::render, components<Body>(), {}, components<Absent>(),
           [&](Registry&, const FrameContext&) { ++runs; }});
    ASSERT_TRUE(s.tick(r, 0.0));
    EXPECT_EQ(runs, 1);
}

TEST(FixedStep, AccumulatorTakesWholeStepsAndCarriesTheRemainder) {
    Registry r;
    r.emplace<Body>(r.create());
    int sim_runs = 0;
    Scheduler s(SchedulerSettings{.fixed_dt_s = 0.01, .max_steps_per_frame = 10, .time_scale = 1});
    s.add({"sim", Phase::simulation, {}, components<Body>(), {}, [&](Registry&, const FrameContext&) { ++sim_runs; }});
    auto report = s.tick(r, 0.025);
    ASSERT_TRUE(report);
    EXPECT_EQ(report->steps, 2);
    report = s.tick(r, 0.005);  // 0.005 carried + 0.005 = one step
    ASSERT_TRUE(report);
    EXPECT_EQ(report->steps, 1);
    EXPECT_EQ(sim_runs, 3);
    EXPECT_NEAR(s.time_s(), 0.03, 1e-12);
}

TEST(FixedStep, HitchIsCappedAndTheExcessDropped) {
    Registry r;
    r.emplace<Body>(r.create());
    std::vector<double> step_sizes;
    Scheduler s(SchedulerSettings{.fixed_dt_s = 1.0 / 60.0, .max_steps_per_frame = 4, .time_scale = 1});
    s.add({"sim", Phase::simulation, {}, components<Body>(), {},
           [&](Registry&, const FrameContext& c) { step_sizes.push_back(c.fixed_dt_s); }});
    auto report = s.tick(r, 0.5);  // a half-second hitch
    ASSERT_TRUE(report);
    EXPECT_EQ(report->steps, 4);  // not 30: the game does not freeze
    EXPECT_NEAR(report->dropped_s, 0.5 - 4.0 / 60.0, 1e-9);
    for (double h : step_sizes) EXPECT_DOUBLE_EQ(h, 1.0 / 60.0);  // never one huge step
    // The next normal frame is a normal frame again: no backlog.
    report = s.tick(r, 1.0 / 60.0);
    ASSERT_TRUE(report);
    EXPECT_EQ(report->steps, 1);
}

TEST(FixedStep, BadFrameTimesAreRejectedAndNothingRuns) {
    Registry r;
    r.emplace<Body>(r.create());
    int runs = 0;
    Scheduler s;
    s.add({"input", Phase::input, {}, components<Body>(), {}, [&](Registry&, const FrameContext&) { ++runs; }});
    for (double bad : {-1.0 / 60.0, std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::infinity()}) {
        auto report = s.tick(r, bad);
        ASSERT_FALSE(report);
        EXPECT_NE(report.error().message.find("frame time"), std::string::npos);
    }
    EXPECT_EQ(runs, 0);
    EXPECT_EQ(s.frame(), 0u);
}

TEST(FixedStep, ASystemTimesSectionsOfItsOwnUnderItsName) {
    // A solver that substeps owns its loop: the scheduler runs it once per fixed step, and
    // it times each section through the context's profiler, in slots listed under it.
    Registry r;
    const Entity body = r.create();
    r.emplace<Body>(body);
    Scheduler s;
    std::uint32_t section = 0;
    int sections_run = 0;
    const std::uint32_t own = s.add({"solver", Phase::simulation, {}, components<Body>(), {},
                                     [&](Registry&, const FrameContext& c) {
                                         ASSERT_NE(c.profiler, nullptr);
                                         for (int k = 0; k < 3; ++k) {
                                             ProfileScope scope(*c.profiler, section);
                                             ++sections_run;
                                         }
                                     }});
    section = s.profiler().add_slot("solver_part", own);
    ASSERT_TRUE(s.tick(r, 2.0 / 60.0));
    EXPECT_EQ(sections_run, 6);
    EXPECT_EQ(s.profiler().stats("solver").runs, 2u);
    EXPECT_EQ(s.profiler().stats("solver_part").runs, 6u);
    EXPECT_EQ(s.profiler().stats("solver_part").parent, "solver");
    EXPECT_NE(s.profiler().table().find("  solver_part"), std::string::npos);
    // Skipped with its system.
    r.remove<Body>(body);
    ASSERT_TRUE(s.tick(r, 1.0 / 60.0));
    EXPECT_EQ(s.profiler().stats("solver").skips, 1u);
    EXPECT_EQ(s.profiler().stats("solver_part").skips, 1u);
}

TEST(FixedStep, TimeScaleSlowsOrStopsSimulation) {
    Registry r;
    r.emplace<Body>(r.create());
    Scheduler s;
    ASSERT_TRUE(s.set_time_scale(0.5));
    int steps = 0;
    for (int i = 0; i < 60; ++i) steps += s.tick(r, 1.0 / 60.0)->steps;
    EXPECT_EQ(steps, 30);
    ASSERT_TRUE(s.set_time_scale(0));
    EXPECT_EQ(s.tick(r, 1.0)->steps, 0);
    EXPECT_FALSE(s.set_time_scale(-1));
    EXPECT_FALSE(s.set_time_scale(std::nan("")));
}

TEST(SchedulerSettings, InvalidSettingsNameTheField) {
    auto bad = Scheduler::create(SchedulerSettings{.fixed_dt_s = 0});
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("fixed_dt_s"), std::string::npos);
    bad = Scheduler::create(SchedulerSettings{.fixed_dt_s = 0.01, .max_steps_per_frame = 0});
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().message.find("max_steps_per_frame"), std::string::npos);
}

}  // namespace
}  // namespace drape
