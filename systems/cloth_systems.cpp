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

// The garments of one fixed step, split into groups that step together: the same substep
// count and constraint rounds. Kept between runs so that a stable scene allocates nothing.
struct ClothStepBatches {
    GarmentBatch all;
    struct Group {
        int substeps = 1;
        int rounds = 1;
        GarmentBatch batch;
    };
    std::vector<Group> groups;
    std::size_t used = 0;

    GarmentBatch& group(int substeps, int rounds) {
        for (std::size_t k = 0; k < used; ++k)
            if (groups[k].substeps == substeps && groups[k].rounds == rounds) return groups[k].batch;
        if (used == groups.size()) groups.emplace_back();
        Group& g = groups[used++];
        g.substeps = substeps;
        g.rounds = rounds;
        g.batch.items.clear();
        return g.batch;
    }
};

// One fixed step of every garment: each takes its own substep count (and rounds), so a
// garment's result does not depend on the others; garments with the same counts step
// together, the three systems in every substep, each in its own profiler scope.
void run_step(Registry& registry, ClothStepBatches& batches, double fixed_dt_s, const ClothSolverSettings& settings,
              FrameProfiler* profiler, const ClothSlots& slots) {
    batches.all.gather(registry);
    if (batches.all.items.empty()) return;
    batches.used = 0;
    for (const GarmentWork& w : batches.all.items) {
        const int substeps = garment_substeps(registry, *w.garment, *w.solver, fixed_dt_s, settings);
        batches.group(substeps, constraint_rounds(*w.garment)).items.push_back(w);
    }
    const auto timed = [&](int k, auto&& run) {
        std::optional<ProfileScope> scope;
        if (profiler != nullptr && slots.timed) scope.emplace(*profiler, slots.slot[static_cast<std::size_t>(k)]);
        run();
    };
    for (std::size_t k = 0; k < batches.used; ++k) {
        GarmentBatch& batch = batches.groups[k].batch;
        const int substeps = batches.groups[k].substeps;
        const int rounds = batches.groups[k].rounds;
        for (int i = 0; i < substeps; ++i) {
            const ClothSubstep sub = make_substep(i, substeps, fixed_dt_s);
            timed(0, [&] { run_cloth_integration(registry, batch, sub); });
            timed(2, [&] { run_cloth_collision_prepare(registry, batch, sub); });
            for (int round = 0; round < rounds; ++round) {
                timed(1, [&] { run_cloth_constraint_round(batch, sub, round); });
                if (collides_after(round, rounds)) timed(2, [&] { run_cloth_collision_round(registry, batch, sub, round); });
            }
            timed(1, [&] { run_cloth_constraint_finish(batch, sub); });
            timed(2, [&] { run_cloth_collision_finish(registry, batch, sub); });
        }
    }
}

}  // namespace

std::uint32_t add_cloth_systems(Scheduler& scheduler, const ClothSolverSettings& settings) {
    auto batch = std::make_shared<ClothStepBatches>();
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
    ClothStepBatches batches;
    run_step(registry, batches, fixed_dt_s, settings, nullptr, ClothSlots{});
}

}  // namespace drape
