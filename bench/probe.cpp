// Probes of a running Drape world for the benchmarks (see probe.hpp).
#include "bench/probe.hpp"

#include <algorithm>

#include "drape/components/ellipsoid_collider.hpp"

namespace drape::bench {

namespace {

bool contains(const std::string& name, const char* word) { return name.find(word) != std::string::npos; }

enum class Group { integrate, collide, other };

Group simulation_group(const std::string& name) {
    if (contains(name, "collision") || contains(name, "collide")) return Group::collide;
    if (contains(name, "integrat") || contains(name, "constraint")) return Group::integrate;
    return Group::other;
}

// The simulation phase's sections (the cloth systems inside the cloth step), by name; a
// simulation system without sections counts as its own.
std::vector<std::string> simulation_sections(const Scheduler& scheduler) {
    const std::vector<std::string> systems = scheduler.system_names(Phase::simulation);
    const auto is_system = [&](const std::string& name) { return std::find(systems.begin(), systems.end(), name) != systems.end(); };
    std::vector<std::string> sections;
    const std::vector<SystemStats> stats = scheduler.profiler().stats();
    for (const std::string& system : systems) {
        bool has_sections = false;
        for (const SystemStats& st : stats)
            if (st.parent == system) {
                sections.push_back(st.name);
                has_sections = true;
            }
        if (!has_sections && is_system(system)) sections.push_back(system);
    }
    return sections;
}

}  // namespace

ClothSystemTime cloth_system_totals(const Scheduler& scheduler) {
    ClothSystemTime t;
    const FrameProfiler& profiler = scheduler.profiler();
    for (const auto& name : scheduler.system_names(Phase::simulation)) t.garment_ms += profiler.stats(name).total_ms;
    for (const auto& name : simulation_sections(scheduler)) {
        const double ms = profiler.stats(name).total_ms;
        switch (simulation_group(name)) {
            case Group::integrate: t.integrate_ms += ms; break;
            case Group::collide: t.collide_ms += ms; break;
            case Group::other: break;
        }
    }
    for (const auto& name : scheduler.system_names(Phase::animation)) t.animation_ms += profiler.stats(name).total_ms;
    for (const auto& name : scheduler.system_names(Phase::skinning)) t.skinning_ms += profiler.stats(name).total_ms;
    t.frame_ms = profiler.mean_frame_ms() * static_cast<double>(profiler.frames());
    return t;
}

ClothSystemTime per_frame(const ClothSystemTime& later, const ClothSystemTime& earlier, double frames) {
    const double f = frames > 0 ? 1.0 / frames : 0.0;
    return {(later.integrate_ms - earlier.integrate_ms) * f, (later.collide_ms - earlier.collide_ms) * f,
            (later.garment_ms - earlier.garment_ms) * f,     (later.animation_ms - earlier.animation_ms) * f,
            (later.skinning_ms - earlier.skinning_ms) * f,   (later.frame_ms - earlier.frame_ms) * f};
}

std::string cloth_system_grouping(const Scheduler& scheduler) {
    std::string integrate, collide, other;
    auto append = [](std::string& list, const std::string& name) { list += (list.empty() ? "`" : " + `") + name + "`"; };
    for (const auto& name : simulation_sections(scheduler)) {
        switch (simulation_group(name)) {
            case Group::integrate: append(integrate, name); break;
            case Group::collide: append(collide, name); break;
            case Group::other: append(other, name); break;
        }
    }
    std::string text = "integrate = " + (integrate.empty() ? std::string("(none)") : integrate) +
                       "; collide = " + (collide.empty() ? std::string("(none)") : collide) +
                       "; garment total = the simulation phase's systems (`" + [&] {
                           std::string systems;
                           for (const auto& name : scheduler.system_names(Phase::simulation))
                               systems += (systems.empty() ? "" : "`, `") + name;
                           return systems;
                       }() + "`), substep rule included";
    if (!other.empty()) text += " (also " + other + ")";
    return text;
}

StructuralSprings structural_springs(const Fabric& topology) {
    StructuralSprings s;
    for (const SpringPhase* phase : {&topology.warp1, &topology.warp2, &topology.weft}) {
        for (std::size_t i = 0; i < phase->size(); ++i) {
            s.springs.push_back({phase->a[i], phase->b[i]});
            s.rest_m.push_back(phase->rest_m[i]);
        }
    }
    return s;
}

std::vector<std::uint32_t> pinned_particles(const Garment& garment) {
    std::vector<std::uint32_t> pinned;
    for (Eigen::Index i = 0; i < garment.state.inv_mass.size(); ++i)
        if (garment.state.inv_mass[i] == 0) pinned.push_back(static_cast<std::uint32_t>(i));
    return pinned;
}

std::vector<Affine3> collider_worlds(const Registry& registry, const Garment& garment) {
    std::vector<Affine3> worlds;
    for (Entity e : garment.body.colliders)
        if (const auto* c = registry.try_get<EllipsoidCollider>(e)) worlds.push_back(c->world);
    return worlds;
}

std::vector<Affine3> all_collider_worlds(const Registry& registry) {
    std::vector<Affine3> worlds;
    const_cast<Registry&>(registry).view<EllipsoidCollider>().each(
        [&](Entity, EllipsoidCollider& c) { worlds.push_back(c.world); });
    return worlds;
}

}  // namespace drape::bench
