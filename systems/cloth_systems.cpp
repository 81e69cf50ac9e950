// The cloth step; see cloth_systems.hpp.
#include "drape/systems/cloth_systems.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <optional>

#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/engine/core/jobs.hpp"
#include "drape/systems/cloth/garment_batch.hpp"
#include "drape/systems/cloth_collision_system.hpp"
#include "drape/systems/cloth_constraint_system.hpp"
#include "drape/systems/cloth_integration_system.hpp"

namespace drape {
namespace {

// Slots of the three cloth systems in the scheduler's profiler (none when untimed).
struct ClothSlots {
    std::array<std::uint32_t, 3> slot{};
    bool timed = false;
};

// How a garment's stages are timed: each system call in its own profiler scope (one
// garment stepping alone: the frame budget shows every run), or added up per thread (many
// garments stepping in parallel: shared out afterwards, see run_step).
struct StageTimes {
    std::array<std::int64_t, 3> ns{};
};

// One fixed step of one garment (a batch of one): the three cloth systems in every substep,
// in the order of systems/cloth/garment_step.hpp.
void step_one(const Registry& registry, const GarmentBatch& one, int substeps, int rounds, double fixed_dt_s,
              FrameProfiler* profiler, const ClothSlots& slots, StageTimes* times) {
    const auto timed = [&](int k, auto&& run) {
        if (times != nullptr) {
            const auto start = FrameProfiler::Clock::now();
            run();
            times->ns[static_cast<std::size_t>(k)] += (FrameProfiler::Clock::now() - start).count();
            return;
        }
        std::optional<ProfileScope> scope;
        if (profiler != nullptr && slots.timed) scope.emplace(*profiler, slots.slot[static_cast<std::size_t>(k)]);
        run();
    };
    for (int i = 0; i < substeps; ++i) {
        const ClothSubstep sub = make_substep(i, substeps, fixed_dt_s);
        timed(0, [&] { run_cloth_integration(registry, one, sub); });
        timed(2, [&] { run_cloth_collision_prepare(registry, one, sub); });
        for (int round = 0; round < rounds; ++round) {
            timed(1, [&] { run_cloth_constraint_round(one, sub, round); });
            if (collides_after(round, rounds)) timed(2, [&] { run_cloth_collision_round(registry, one, sub, round); });
        }
        timed(1, [&] { run_cloth_constraint_finish(one, sub); });
        timed(2, [&] { run_cloth_collision_finish(registry, one, sub); });
    }
}

// One fixed step of every garment. Each garment takes its own substep count and rounds, so
// its result does not depend on the others, and steps through all of them before the next
// garment is touched: a crowd's garments do not evict each other from the cache between
// stages. Several garments step in parallel (TBB, one task per garment; each writes only
// itself, so any number of threads gives the same bytes). Their stages are then timed per
// thread, and the step's wall time is shared out to the three profiler slots by those
// times (one run each per fixed step); a garment stepping alone has every system call timed.
void run_step(Registry& registry, GarmentBatch& all, double fixed_dt_s, const ClothSolverSettings& settings,
              FrameProfiler* profiler, const ClothSlots& slots) {
    all.gather(registry);
    if (all.items.empty()) return;
    const auto step_item = [&](const GarmentWork& w, StageTimes* times) {
        const GarmentBatch one{{w}, {}};
        const int substeps = garment_substeps(registry, *w.garment, *w.solver, fixed_dt_s, settings);
        step_one(registry, one, substeps, constraint_rounds(*w.garment), fixed_dt_s, profiler, slots, times);
    };
    if (all.items.size() == 1) {
        step_item(all.items.front(), nullptr);
        return;
    }
    const bool timed = profiler != nullptr && slots.timed && profiler->timing();
    std::vector<StageTimes> per_item(timed ? all.items.size() : 0);
    const auto start = FrameProfiler::Clock::now();
    job_system().parallel_for(all.items.size(), [&](std::size_t i) { step_item(all.items[i], timed ? &per_item[i] : nullptr); });
    const auto end = FrameProfiler::Clock::now();
    if (profiler == nullptr || !slots.timed) return;
    if (!timed) {
        for (std::uint32_t slot : slots.slot) profiler->record_untimed_run(slot);
        return;
    }
    StageTimes sum;
    for (const StageTimes& t : per_item)
        for (std::size_t k = 0; k < sum.ns.size(); ++k) sum.ns[k] += t.ns[k];
    const double total = static_cast<double>(sum.ns[0] + sum.ns[1] + sum.ns[2]);
    const double wall = static_cast<double>((end - start).count());
    auto at = start;
    for (std::size_t k = 0; k < sum.ns.size(); ++k) {
        const auto share = FrameProfiler::Clock::duration(
            static_cast<FrameProfiler::Clock::rep>(total > 0 ? wall * static_cast<double>(sum.ns[k]) / total : 0));
        profiler->record_run(slots.slot[k], at, at + share);
        at += share;
    }
}

}  // namespace

std::uint32_t add_cloth_systems(Scheduler& scheduler, const ClothSolverSettings& settings) {
    auto batch = std::make_shared<GarmentBatch>();
    auto slots = std::make_shared<ClothSlots>();  // filled once the step has its own slot
    System step{"cloth", Phase::simulation, {}, components<Garment>(), components<EllipsoidCollider, Skeleton, Transform>(),
                [batch, settings, slots](Registry& registry, const FrameContext& context) {
                    run_step(registry, *batch, context.fixed_dt_s, settings, context.profiler, *slots);
                }};
    const std::uint32_t own = scheduler.add(std::move(step));
    // Slot indices, not references: they stay valid when the scheduler moves.
    std::size_t k = 0;
    for (const char* name : {"cloth_integration", "cloth_constraint", "cloth_collision"})
        slots->slot[k++] = scheduler.profiler().add_slot(name, own);
    slots->timed = true;
    return own;
}

void step_cloth(Registry& registry, double fixed_dt_s, const ClothSolverSettings& settings) {
    GarmentBatch all;
    run_step(registry, all, fixed_dt_s, settings, nullptr, ClothSlots{});
}

}  // namespace drape
