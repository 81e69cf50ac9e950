// The cloth step; see cloth_systems.hpp.
#include "systems/cloth_systems.hpp"

#include <algorithm>
#include <array>
#include <memory>
#include <optional>

#include "components/ellipsoid_collider.hpp"
#include "components/garment.hpp"
#include "components/skeleton.hpp"
#include "components/transform.hpp"
#include "systems/cloth/garment_batch.hpp"
#include "systems/cloth_collision_system.hpp"
#include "systems/cloth_constraint_system.hpp"
#include "systems/cloth_integration_system.hpp"

namespace drape {
namespace {

// Slots of the three cloth systems in the scheduler's profiler (none when untimed).
struct ClothSlots {
    std::array<std::uint32_t, 3> slot{};
    bool timed = false;
};

// One fixed step of every garment in `batch`: the shared substep count, then the three
// systems in every substep, each in its own profiler scope.
void run_step(Registry& registry, GarmentBatch& batch, double fixed_dt_s, const ClothSolverSettings& settings,
              FrameProfiler* profiler, const ClothSlots& slots) {
    batch.gather(registry);
    if (batch.items.empty()) return;
    int substeps = 1;
    for (const GarmentWork& w : batch.items)
        substeps = std::max(substeps, garment_substeps(registry, *w.garment, *w.solver, fixed_dt_s, settings));
    const auto timed = [&](int k, auto&& run) {
        std::optional<ProfileScope> scope;
        if (profiler != nullptr && slots.timed) scope.emplace(*profiler, slots.slot[static_cast<std::size_t>(k)]);
        run();
    };
    int rounds = 1;
    for (const GarmentWork& w : batch.items) rounds = std::max(rounds, constraint_rounds(*w.garment));
    for (int i = 0; i < substeps; ++i) {
        const ClothSubstep sub = make_substep(i, substeps, fixed_dt_s);
        timed(0, [&] { run_cloth_integration(registry, batch, sub); });
        timed(2, [&] { run_cloth_collision_prepare(registry, batch, sub); });
        for (int round = 0; round < rounds; ++round) {
            timed(1, [&] { run_cloth_constraint_round(batch, sub, round); });
            timed(2, [&] { run_cloth_collision_round(registry, batch, sub, round); });
        }
        timed(1, [&] { run_cloth_constraint_finish(batch, sub); });
        timed(2, [&] { run_cloth_collision_finish(registry, batch, sub); });
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
    GarmentBatch batch;
    run_step(registry, batch, fixed_dt_s, settings, nullptr, ClothSlots{});
}

}  // namespace drape
