// Worlds built from scene descriptions; see world.hpp.
#include "drape/game/world.hpp"

#include <cmath>
#include <map>

#include <tbb/global_control.h>

#include "drape/components/animation_player.hpp"
#include "drape/components/character.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/engine/assets/character_import.hpp"
#include "drape/game/collider_overrides.hpp"
#include "drape/game/scene_file.hpp"
#include "drape/game/scene_garment_parameters.hpp"
#include "drape/systems/character/body_cache.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character_systems.hpp"
#include "drape/systems/character/spawn.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_config.hpp"
#include "drape/systems/cloth_systems.hpp"
#include "drape/systems/teleport_guard_system.hpp"

#ifdef DRAPE_HAVE_RENDER
#include "drape/engine/render/renderer.hpp"
#include "drape/systems/render_system.hpp"
#include "drape/systems/skin_cover_system.hpp"
#include "drape/systems/skinning_system.hpp"
#endif

namespace drape {

namespace fs = std::filesystem;

namespace {

constexpr Real degrees = Real(3.14159265358979323846 / 180.0);

}  // namespace

bool render_available() noexcept {
#ifdef DRAPE_HAVE_RENDER
    return true;
#else
    return false;
#endif
}

Result<World> build_world(const SceneDescription& scene, const WorldOptions& options) {
    if (auto ok = validate(scene); !ok) return std::unexpected(ok.error());
    SchedulerSettings settings;
    settings.fixed_dt_s = scene.solver.fixed_dt_s;
    settings.max_steps_per_frame = scene.solver.max_steps_per_frame;
    settings.time_scale = scene.solver.time_scale;
    auto scheduler = Scheduler::create(settings);
    if (!scheduler) return std::unexpected(scheduler.error());

    World world;
    world.scene = scene;
    world.scheduler = std::move(*scheduler);
    if (scene.solver.threads > 0)
        world.thread_limit = std::make_shared<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                                   static_cast<std::size_t>(scene.solver.threads));
    world.scheduler.profiler().set_timing(options.profile);

    // Characters (one import and one fitted body per file), then collider overrides.
    struct Loaded {
        std::shared_ptr<const CharacterAsset> asset;
        CharacterBody body;
    };
    std::map<fs::path, Loaded> loaded;
    const fs::path body_cache = !options.body_cache.empty() ? options.body_cache : body_cache_from_environment();
    for (std::size_t i = 0; i < scene.characters.size(); ++i) {
        const CharacterDescription& c = scene.characters[i];
        const std::string field = "characters[" + std::to_string(i) + "].file";
        Loaded& character = loaded[c.file];
        if (!character.asset) {
            auto imported = import_character(c.file);
            if (!imported) return fail(located(c.where, field, imported.error().message));
            auto body = fit_character_body(**imported, c.file, FitOptions{}, body_cache);
            if (!body) return fail(located(c.where, field, body.error().message));
            character = {*imported, std::move(*body)};
            world.warnings.insert(world.warnings.end(), character.asset->warnings.begin(), character.asset->warnings.end());
        }
        const std::shared_ptr<const CharacterAsset>& asset = character.asset;
        SpawnOptions spawn;
        spawn.transform.position = c.position_m;
        spawn.transform.rotation = c.rotation();
        spawn.transform.scale = c.scale;
        spawn.clip = c.clip;
        spawn.speed = c.speed;
        spawn.in_place = c.in_place;
        spawn.start_time_s = c.start_s;
        if (!c.clip.empty()) {
            if (auto clip = find_clip(*asset, c.clip); !clip)
                return fail(located(c.where, "characters[" + std::to_string(i) + "].clip", clip.error().message));
        }
        auto entity = spawn_character(world.registry, asset, character.body, spawn);
        if (!entity) return fail(located(c.where, "characters[" + std::to_string(i) + "]", entity.error().message));
        world.characters.push_back(*entity);
        if (auto ok = apply_collider_overrides(world.registry, *entity, i, scene.colliders, *asset); !ok)
            return std::unexpected(ok.error());
    }

    // Systems: characters, teleport guard, cloth (+ fixed substeps), render.
    add_character_systems(world.scheduler);
    world.scheduler.add(make_teleport_guard_system(scene.solver.teleport_threshold_m, world.teleports));
    ClothSolverSettings cloth;
    cloth.fixed_substeps = scene.solver.substeps;
    cloth.max_surface_travel_m = static_cast<Real>(scene.solver.max_surface_travel_m);
    cloth.max_substeps = scene.solver.max_substeps;
    add_cloth_systems(world.scheduler, cloth);
    // The garment builders fit around placed colliders (overrides included): one pass of
    // the skinning phase (colliders) places them before the first step.
    world.scheduler.run_phase(world.registry, Phase::skinning, FrameContext{.fixed_dt_s = scene.solver.fixed_dt_s});

    // Garments.
    for (std::size_t i = 0; i < scene.garments.size(); ++i) {
        const GarmentDescription& g = scene.garments[i];
        const std::string field = "garments[" + std::to_string(i) + "]";
        const Entity body = world.characters.at(static_cast<std::size_t>(g.character));
        auto params = tube_params(g);
        if (!params) return fail(located(g.where, field, params.error().message));
        const Result<Entity> garment = g.type == GarmentType::skirt ? attach_skirt(world.registry, body, *params)
                                                                    : attach_dress(world.registry, body, *params);
        if (!garment) return fail(located(g.where, field, garment.error().message));
        world.garments.push_back(*garment);
    }
    world.watch = GarmentWatch(world.registry, world.garments);
    world.scheduler.profiler().reset();  // the profile is of played frames, not of the set-up pass

    // Renderer.
    if (options.render) {
#ifdef DRAPE_HAVE_RENDER
        RenderSettings rs;
        rs.width = options.width;
        rs.height = options.height;
        rs.target = options.window ? RenderTarget::window : RenderTarget::offscreen;
        auto renderer = Renderer::create(rs);
        if (!renderer) return std::unexpected(renderer.error());
        world.renderer = std::shared_ptr<Renderer>(std::move(*renderer));
        Camera& camera = world.renderer->camera();
        const CameraDescription& c = scene.camera;
        camera.follow = c.follow;
        camera.target = c.target_m;
        camera.distance_m = c.distance_m;
        camera.yaw_rad = c.yaw_deg * degrees;
        camera.pitch_rad = c.pitch_deg * degrees;
        camera.fov_y_rad = c.fov_deg * degrees;
        // The mesh is skinned for drawing only, once per frame, just before it is drawn.
        world.scheduler.add(make_skinning_system());
        world.scheduler.add(make_skin_cover_system());
        world.scheduler.add(make_render_system(*world.renderer));
#else
        return fail("rendering: this build has no render module (configured with -DDRAPE_RENDER=OFF)");
#endif
    }
    return world;
}

Result<FrameReport> step_world(World& world, double frame_dt_s) {
    if (std::isfinite(frame_dt_s) && frame_dt_s > world.scene.solver.max_frame_dt_s) frame_dt_s = world.scene.solver.max_frame_dt_s;
    auto report = world.scheduler.tick(world.registry, frame_dt_s);
    if (report) world.watch.sample(world.registry);
    return report;
}

void reset_garments(World& world) {
    for (Entity g : world.garments) {
        reset_garment(world.registry, g);
        ++world.teleports->resets;
    }
}

void set_garment_model(World& world, ClothModel model) {
    for (std::size_t i = 0; i < world.garments.size(); ++i) {
        set_garment_model(world.registry, world.garments[i], model);
        if (i < world.scene.garments.size()) world.scene.garments[i].model = model;
    }
}

Result<void> set_time_scale(World& world, double scale) {
    if (auto ok = world.scheduler.set_time_scale(scale); !ok) return ok;
    world.scene.solver.time_scale = scale;
    return {};
}

RunStats run_stats(const World& world) {
    RunStats stats = make_run_stats(world.scheduler.profiler(), world.scheduler.settings().fixed_dt_s, world.watch, world.registry);
    for (std::size_t i = 0; i < world.characters.size(); ++i) {
        CharacterStats c;
        if (i < world.scene.characters.size()) c.file = world.scene.characters[i].file.string();
        if (const auto* character = world.registry.try_get<Character>(world.characters[i])) c.height_m = character->height_m;
        if (const auto* player = world.registry.try_get<AnimationPlayer>(world.characters[i]); player && player->clip)
            c.clip = player->clip->name;
        stats.characters.push_back(std::move(c));
    }
    return stats;
}

bool has_nonfinite(const World& world) {
    for (Entity e : world.garments)
        if (const Garment* g = world.registry.try_get<Garment>(e); g && (!g->state.x.allFinite() || !g->state.v.allFinite())) return true;
    for (Entity e : world.characters) {
        if (const SkinnedMesh* m = world.registry.try_get<SkinnedMesh>(e); m && !m->positions.allFinite()) return true;
        if (const Skeleton* s = world.registry.try_get<Skeleton>(e))
            for (const Affine3& bone : s->skinning)
                if (!bone.matrix().allFinite()) return true;
    }
    return false;
}

}  // namespace drape
