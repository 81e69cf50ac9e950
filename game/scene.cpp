#include "game/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <unistd.h>

#include <tbb/global_control.h>

#include "components/character.hpp"
#include "components/ellipsoid_collider.hpp"
#include "components/garment.hpp"
#include "components/skeleton.hpp"
#include "components/skinned_mesh.hpp"
#include "components/transform.hpp"
#include "engine/assets/character_import.hpp"
#include "systems/character/character_systems.hpp"
#include "systems/character/spawn.hpp"
#include "game/scene_garment_parameters.hpp"
#include "systems/cloth/garment_config.hpp"
#include "systems/cloth_systems.hpp"
#include "systems/teleport_guard_system.hpp"
#include "systems/cloth/garment_builder.hpp"

#ifdef DRAPE_HAVE_RENDER
#include "engine/render/renderer.hpp"
#include "systems/render_system.hpp"
#endif

namespace drape {

namespace fs = std::filesystem;

bool render_available() noexcept {
#ifdef DRAPE_HAVE_RENDER
    return true;
#else
    return false;
#endif
}

fs::path asset_dir() {
    std::error_code ec;
    auto has_avatar = [&](const fs::path& dir) { return fs::is_regular_file(dir / "avatar.glb", ec); };
    if (const char* env = std::getenv("DRAPE_ASSETS"); env != nullptr && *env != '\0') return fs::path(env);
    if (has_avatar("assets")) return fs::absolute("assets", ec);
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec)
        for (const fs::path& candidate : {exe.parent_path() / "../assets", exe.parent_path() / "../share/drape/assets"})
            if (has_avatar(candidate)) return candidate.lexically_normal();
#ifdef DRAPE_SOURCE_ASSETS
    return fs::path(DRAPE_SOURCE_ASSETS);
#else
    return fs::absolute("assets", ec);
#endif
}

fs::path default_avatar_path() { return asset_dir() / "avatar.glb"; }

SceneDescription sample_scene() {
    SceneDescription scene;
    scene.description = "Drape's sample scene: the default avatar walking in place in a skirt";
    CharacterDescription avatar;
    avatar.file = default_avatar_path();
    avatar.clip = "Walk";
    scene.characters.push_back(avatar);
    GarmentDescription skirt;
    skirt.type = GarmentType::skirt;
    skirt.color = Vec3(0.75f, 0.12f, 0.18f);
    scene.garments.push_back(skirt);
    return scene;
}

namespace {

constexpr Real degrees = Real(3.14159265358979323846 / 180.0);

Quat euler_deg(const Vec3& deg) {
    return Quat(Eigen::AngleAxis<Real>(deg.y() * degrees, Vec3::UnitY()) * Eigen::AngleAxis<Real>(deg.x() * degrees, Vec3::UnitX()) *
                Eigen::AngleAxis<Real>(deg.z() * degrees, Vec3::UnitZ()));
}

// Applies the scene's collider overrides for one character (after spawn, before dressing).
Result<void> apply_collider_overrides(World& world, const SceneDescription& scene, std::size_t index, const CharacterAsset& asset) {
    Registry& registry = world.registry;
    const Entity character = world.characters[index];
    for (std::size_t k = 0; k < scene.colliders.size(); ++k) {
        const ColliderOverride& o = scene.colliders[k];
        if (o.character != static_cast<int>(index)) continue;
        const std::string field = "colliders[" + std::to_string(k) + "].bone";
        const int bone = asset.skeleton ? asset.skeleton->find(o.bone) : -1;
        if (bone < 0) {
            std::string bones;
            if (asset.skeleton)
                for (std::size_t b = 0; b < asset.skeleton->bone_names.size() && b < 12; ++b)
                    bones += (b ? ", " : "") + asset.skeleton->bone_names[b];
            return fail(located(o.where, field, "no bone \"" + o.bone + "\" in " + asset.source.string() + " (bones: " + bones +
                                                    (asset.skeleton && asset.skeleton->size() > 12 ? ", ..." : "") + ")"));
        }
        std::vector<Entity> on_bone;
        for (Entity e : colliders_of(registry, character))
            if (const auto* c = registry.try_get<EllipsoidCollider>(e); c && c->bone == bone) on_bone.push_back(e);
        if (o.remove) {
            if (on_bone.empty()) return fail(located(o.where, field, "bone \"" + o.bone + "\" has no fitted ellipsoid to remove"));
            for (Entity e : on_bone) registry.destroy(e);
            continue;
        }
        if (on_bone.empty()) {  // a new ellipsoid on this bone
            const Entity e = registry.create();
            EllipsoidCollider& c = registry.emplace<EllipsoidCollider>(e);
            c.character = character;
            c.bone = bone;
            on_bone.push_back(e);
        }
        for (Entity e : on_bone) {
            EllipsoidCollider& c = registry.get<EllipsoidCollider>(e);
            if (o.center_m) c.center = *o.center_m;
            if (o.radii_m) c.radii_m = *o.radii_m;
            if (o.rotation_deg) c.rotation = euler_deg(*o.rotation_deg);
            c.initialised = false;
        }
    }
    return {};
}

}  // namespace

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

    // Characters (one import per file), then collider overrides.
    std::map<fs::path, std::shared_ptr<const CharacterAsset>> assets;
    for (std::size_t i = 0; i < scene.characters.size(); ++i) {
        const CharacterDescription& c = scene.characters[i];
        const std::string field = "characters[" + std::to_string(i) + "].file";
        auto& asset = assets[c.file];
        if (!asset) {
            auto imported = import_character(c.file);
            if (!imported) return fail(located(c.where, field, imported.error().message));
            asset = *imported;
            world.warnings.insert(world.warnings.end(), asset->warnings.begin(), asset->warnings.end());
        }
        SpawnOptions spawn;
        spawn.transform.position = c.position_m;
        spawn.transform.rotation = c.rotation();
        spawn.transform.scale = c.scale;
        spawn.clip = c.clip;
        spawn.speed = c.speed;
        spawn.in_place = c.in_place;
        if (!c.clip.empty()) {
            if (auto clip = find_clip(*asset, c.clip); !clip)
                return fail(located(c.where, "characters[" + std::to_string(i) + "].clip", clip.error().message));
        }
        auto entity = spawn_character(world.registry, asset, spawn);
        if (!entity) return fail(located(c.where, "characters[" + std::to_string(i) + "]", entity.error().message));
        world.characters.push_back(*entity);
        if (auto ok = apply_collider_overrides(world, scene, i, *asset); !ok) return std::unexpected(ok.error());
    }

    // Systems: characters, teleport guard, cloth (+ fixed substeps), render.
    add_character_systems(world.scheduler);
    world.scheduler.add(make_teleport_guard_system(scene.solver.teleport_threshold_m, world.teleports));
    ClothSolverSettings cloth;
    cloth.fixed_substeps = scene.solver.substeps;
    add_cloth_systems(world.scheduler, cloth);
    // The garment builders fit around placed colliders (overrides included): one skinning
    // pass (skinning, colliders) places them before the first step.
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
    return make_run_stats(world.scheduler.profiler(), world.scheduler.settings().fixed_dt_s, world.watch, world.registry);
}

bool has_nonfinite(const World& world) {
    for (Entity e : world.garments)
        if (const Garment* g = world.registry.try_get<Garment>(e); g && (!g->state.x.allFinite() || !g->state.v.allFinite())) return true;
    for (Entity e : world.characters)
        if (const SkinnedMesh* m = world.registry.try_get<SkinnedMesh>(e); m && !m->positions.allFinite()) return true;
    return false;
}

}  // namespace drape
