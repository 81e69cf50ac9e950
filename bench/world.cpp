// Benchmark worlds (see world.hpp).
#include "bench/world.hpp"

#include <cmath>

#include "drape/game/asset_paths.hpp"
#include "drape/game/sample_scene.hpp"

namespace drape::bench {

SceneDescription scene_for(const WorldSpec& spec) {
    SceneDescription scene = sample_scene();
    const CharacterDescription avatar = scene.characters.empty() ? CharacterDescription{} : scene.characters.front();
    scene.characters.clear();
    scene.garments.clear();
    scene.colliders.clear();
    const int columns = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(spec.walkers)))));
    for (int i = 0; i < spec.walkers; ++i) {
        CharacterDescription c = avatar;
        if (c.file.empty()) c.file = default_avatar_path();
        c.position_m = Vec3(1.5f * static_cast<Real>(i % columns), 0, -1.5f * static_cast<Real>(i / columns));
        c.in_place = spec.in_place;
        c.start_s = spec.phase_step_s * i;
        scene.characters.push_back(c);
        GarmentDescription g;
        g.type = spec.garment;
        g.character = i;
        g.model = spec.model;
        g.integrator = spec.integrator;
        g.warp_solve = spec.warp_solve;
        g.collision = spec.collision;
        if (spec.particles > 0) g.parameters.push_back({"particles", static_cast<double>(spec.particles)});
        // The paper's scheme as written: eq. 2 feels the body's whole acceleration.
        if (spec.integrator == ClothIntegrator::paper) g.parameters.push_back({"inertia_max_fall_m_s2", 0.0});
        scene.garments.push_back(g);
    }
    scene.solver.substeps = spec.substeps;
    scene.solver.fixed_dt_s = spec.fixed_dt_s;
    scene.solver.time_scale = spec.time_scale;
    scene.solver.threads = spec.threads;
    return scene;
}

Result<World> build_bench_world(const WorldSpec& spec) {
    const SceneDescription scene = scene_for(spec);
    for (const auto& c : scene.characters) {
        std::error_code ec;
        if (!std::filesystem::exists(c.file, ec))
            return fail(c.file.string() + ": default avatar not found (set DRAPE_ASSETS or run from the source tree)");
    }
    WorldOptions options;
    options.profile = spec.profile;
    options.render = spec.render;
    return build_world(scene, options);
}

std::filesystem::path shared_characters_dir() {
    namespace fs = std::filesystem;
    fs::path shared = fs::path("..") / "shared" / "assets" / "characters";
#ifdef DRAPE_BENCH_SOURCE_DIR
    if (std::error_code ec; fs::is_directory(fs::path(DRAPE_BENCH_SOURCE_DIR) / shared, ec))
        shared = (fs::path(DRAPE_BENCH_SOURCE_DIR) / shared).lexically_normal();
#endif
    return shared;
}

Garment& first_garment(World& world) { return world.registry.get<Garment>(world.garments.at(0)); }

}  // namespace drape::bench
