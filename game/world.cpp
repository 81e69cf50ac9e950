// Worlds built from scene descriptions; see world.hpp.
#include "drape/game/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>

#include <tbb/global_control.h>

#include "drape/components/animation_player.hpp"
#include "drape/components/character.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/ground_plane.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/engine/assets/character_import.hpp"
#include "drape/engine/assets/garment_file.hpp"
#include "drape/game/collider_overrides.hpp"
#include "drape/game/scene_file.hpp"
#include "drape/game/scene_garment_parameters.hpp"
#include "drape/systems/character/body_cache.hpp"
#include "drape/systems/character/character_body.hpp"
#include "drape/systems/character_systems.hpp"
#include "drape/systems/character/spawn.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_config.hpp"
#include "drape/systems/cloth/garment_from_mesh.hpp"
#include "drape/systems/cloth/garment_parameters.hpp"
#include "drape/systems/cloth_systems.hpp"
#include "drape/systems/teleport_guard_system.hpp"

#ifdef DRAPE_HAVE_RENDER
#include "drape/engine/render/renderer.hpp"
#include "drape/systems/garment_surface_system.hpp"
#include "drape/systems/render_system.hpp"
#include "drape/systems/skin_cover_system.hpp"
#include "drape/systems/skinning_system.hpp"
#endif

namespace drape {

namespace fs = std::filesystem;

namespace {

constexpr Real degrees = Real(3.14159265358979323846 / 180.0);

// A mesh without UVs given its derived pattern (derive_pattern), with a line in `warnings`
// saying so; a mesh with UVs is left as it is.
Result<void> derived_pattern(GarmentMeshAsset& mesh, const std::string& field, const fs::path& file, std::vector<std::string>& warnings) {
    if (mesh.uvs.cols() == mesh.positions.cols()) return {};
    auto line = derive_pattern(mesh, field);
    if (!line) return std::unexpected(line.error());
    warnings.push_back(field + ": " + file.string() + ": " + *line);
    return {};
}

// A garment from a file (docs/garments.md) on `body`: its mesh imported, gridded and held
// as MeshGarmentParams says, the cloth from `params` (the scene's material, model, colour,
// weft_stride and fitting_rows); the built-in garments' shape parameters do not apply. A
// file that paints no pins, held at its higher edge instead, adds a line to `warnings`.
// The character's own file (`character`, read as `asset`, fitted as `fit`): a mesh modelled
// into it, in its bind pose (garment_mesh_of_character), whose meshes go to `own`.
Result<Entity> attach_file_garment(Registry& registry, Entity body, const GarmentDescription& g, const TubeParams& params,
                                   const std::string& field, std::vector<std::string>& warnings, const fs::path& character,
                                   const CharacterAsset& asset, const CharacterBody& fit, std::vector<std::size_t>& own) {
    for (const GarmentParameter& p : g.parameters) {
        const GarmentParameterSpec* spec = find_garment_parameter(p.name);
        if (spec == nullptr || !spec->takes_file_garments())
            return fail(field + "." + p.name + ": shapes a built-in garment; a garment from a file has its own shape");
    }
    MeshGarmentParams mp;
    mp.spacing_m = static_cast<Real>(g.spacing_m);
    mp.modelled_on = g.modelled_on;
    mp.weft_stride = params.weft_stride;
    mp.pins = g.pins;
    mp.fitting_rows = params.fitting_rows;
    mp.config = garment_config(params);
    mp.pin_weights = params.pin_weights;
    std::error_code ec;
    if (fs::equivalent(g.file, character, ec)) {
        std::vector<std::size_t> modelled;
        for (const LeftOutMesh& part : fit.left_out)
            if (part.garment) modelled.push_back(part.mesh);
        auto mesh = garment_mesh_of_character(asset, g.mesh, modelled, field, &own);
        if (!mesh) return std::unexpected(mesh.error());
        if (auto pattern = derived_pattern(*mesh, field, g.file, warnings); !pattern) return std::unexpected(pattern.error());
        mp.modelled_on = GarmentPose::bind;
        return attach_mesh_garment(registry, body, *mesh, mp, field);
    }
    auto mesh = import_garment_mesh(g.file, g.mesh);
    if (!mesh) return std::unexpected(mesh.error());
    if (auto pattern = derived_pattern(*mesh, field, g.file, warnings); !pattern) return std::unexpected(pattern.error());
    if (g.pins == PinSource::file && mesh->pin.size() == 0)
        warnings.push_back(field + ": " + g.file.string() + " paints no pins (COLOR_0): held at its higher edge, " +
                           std::to_string(mp.fitting_rows) + (mp.fitting_rows == 1 ? " row" : " rows"));
    return attach_mesh_garment(registry, body, *mesh, mp, field);
}

// Putting the garments on: each was built around its body in the pose its clip starts in;
// it now settles there for solver.settle_s, every body held in that pose (no animation
// step, so the colliders stand still), before the first frame. A garment built straight
// into a stride (a thigh raised into the tube, an arm across it) is pushed out of the body
// and falls still here instead of being flung up over the chest in the played frames.
// These steps are not frames: nothing is drawn, and the stats and the profile start after.
void settle_garments(World& world) {
    const SolverDescription& solver = world.scene.solver;
    if (world.garments.empty() || !(solver.settle_s > 0)) return;
    const int steps = static_cast<int>(std::ceil(solver.settle_s / solver.fixed_dt_s - 1e-9));
    for (int step = 0; step < steps; ++step) {
        const FrameContext context{.fixed_dt_s = solver.fixed_dt_s, .time_s = step * solver.fixed_dt_s, .step = step, .steps = steps};
        world.scheduler.run_phase(world.registry, Phase::skinning, context);
        world.scheduler.run_phase(world.registry, Phase::simulation, context);
    }
}

}  // namespace

bool render_available() noexcept {
#ifdef DRAPE_HAVE_RENDER
    return true;
#else
    return false;
#endif
}

namespace {

// Submesh `k` of `skin` not drawn (nothing for an index past its submeshes).
void hide_submesh(SkinnedMesh& skin, std::size_t k) {
    if (k >= skin.mesh->submeshes.size()) return;
    skin.hidden.resize(skin.mesh->submeshes.size(), 0);
    skin.hidden[k] = 1;
}

/// How far to raise a character placed by `t` so that its lowest point in the bind pose
/// rests on the floor, when that point lies more than a tenth of its height from its
/// origin's level (a file whose origin is at its feet, soles a little below or above it,
/// stays where it is put).
std::optional<Real> floor_lift(const CharacterAsset& asset, const Transform& t) {
    if (!asset.mesh || asset.mesh->bind_positions.cols() == 0) return std::nullopt;
    const Matrix3X posed = (t.rotation.toRotationMatrix() * static_cast<Real>(t.scale)) * asset.mesh->bind_positions;
    const Real low = posed.row(1).minCoeff(), high = posed.row(1).maxCoeff();
    if (!std::isfinite(low) || !std::isfinite(high) || std::abs(low) <= Real(0.1) * (high - low)) return std::nullopt;
    return -low;
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

    // Characters (one import and one fitted body per file and fit), then collider overrides.
    struct Loaded {
        std::shared_ptr<const CharacterAsset> asset;
        CharacterBody body;
    };
    std::map<std::pair<fs::path, double>, Loaded> loaded;
    const fs::path body_cache = !options.body_cache.empty() ? options.body_cache : body_cache_from_environment();
    for (std::size_t i = 0; i < scene.characters.size(); ++i) {
        const CharacterDescription& c = scene.characters[i];
        const std::string field = "characters[" + std::to_string(i) + "].file";
        Loaded& character = loaded[{c.file, c.thicken_thin_trunk_m}];
        if (!character.asset) {
            auto imported = import_character(c.file);
            if (!imported) return fail(located(c.where, field, imported.error().message));
            FitOptions fit_options;
            fit_options.thicken_thin_trunk_m = c.thicken_thin_trunk_m;
            auto body = fit_character_body(**imported, c.file, fit_options, body_cache);
            if (!body) return fail(located(c.where, field, body.error().message));
            character = {*imported, std::move(*body)};
            world.warnings.insert(world.warnings.end(), character.asset->warnings.begin(), character.asset->warnings.end());
            // Where Drape had to guess, one line each: the units, the landmarks.
            if (character.asset->scale_source == ScaleSource::fallback)
                world.warnings.push_back(c.file.string() + ": units: " + character.asset->units_note);
            if (!character.body.landmarks)
                world.warnings.push_back(character.body.landmarks_error +
                                         "; garments hang at a fixed share of its height, around the mean of its ellipsoids");
        }
        std::shared_ptr<const CharacterAsset> asset = character.asset;
        if (!c.motion.empty()) {
            // A BVH motion: retargeted onto this skeleton, played as the character's clip.
            std::vector<std::string> notes;
            auto motion = import_bvh_motion(c.motion, *asset->skeleton, MotionRetarget{c.motion_bones}, &notes);
            if (!motion) return fail(located(c.where, "characters[" + std::to_string(i) + "].motion", motion.error().message));
            world.warnings.insert(world.warnings.end(), notes.begin(), notes.end());
            auto with_motion = std::make_shared<CharacterAsset>(*asset);
            with_motion->clips.push_back(*motion);
            asset = std::move(with_motion);
        }
        SpawnOptions spawn;
        spawn.transform.position = c.position_m;
        spawn.transform.rotation = c.rotation();
        spawn.transform.scale = c.scale;
        if (scene.ground) {
            // On the floor: a file whose origin is not at its feet (a model centred on its
            // origin) stands with its lowest point on the floor instead of through it.
            if (const auto lift = floor_lift(*asset, spawn.transform)) {
                spawn.transform.position.y() += *lift;
                char line[160];
                std::snprintf(line, sizeof line, ": placed on the floor: its lowest point lies %.2f m %s its origin", std::abs(*lift),
                              *lift > 0 ? "below" : "above");
                world.warnings.push_back(c.file.string() + line);
            }
        }
        spawn.clip = c.motion.empty() ? c.clip : std::to_string(asset->clips.size() - 1);
        spawn.speed = c.speed;
        spawn.in_place = c.in_place;
        spawn.start_time_s = c.start_s;
        if (!c.clip.empty()) {  // (with a motion there is none: the motion is the clip)
            if (auto clip = find_clip(*asset, c.clip); !clip)
                return fail(located(c.where, "characters[" + std::to_string(i) + "].clip", clip.error().message));
        } else if (const auto choice = choose_default_clip(*asset); c.motion.empty() && choice && choice->fell_back) {
            const std::string line = c.file.string() + ": clip: no walk and no looping locomotion clip; playing " + choice->reason;
            if (std::find(world.warnings.begin(), world.warnings.end(), line) == world.warnings.end()) world.warnings.push_back(line);
        }
        auto entity = spawn_character(world.registry, asset, character.body, spawn);
        if (!entity) return fail(located(c.where, "characters[" + std::to_string(i) + "]", entity.error().message));
        world.characters.push_back(*entity);
        if (auto ok = apply_collider_overrides(world.registry, *entity, i, scene.colliders, *asset); !ok)
            return std::unexpected(ok.error());
    }

    // The floor the garments fall onto.
    if (scene.ground) world.registry.emplace<GroundPlane>(world.registry.create(), GroundPlane{.height_m = 0});

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
        const CharacterDescription& worn_by = scene.characters.at(static_cast<std::size_t>(g.character));
        const Loaded& character = loaded.at({worn_by.file, worn_by.thicken_thin_trunk_m});
        std::vector<std::size_t> own;
        const Result<Entity> garment = !g.file.empty() ? attach_file_garment(world.registry, body, g, *params, field, world.warnings,
                                                                             worn_by.file, *character.asset, character.body, own)
                                       : g.type == GarmentType::skirt ? attach_skirt(world.registry, body, *params)
                                                                      : attach_dress(world.registry, body, *params);
        if (!garment) {
            // Errors from a file's garment are already named by the field.
            const std::string& why = garment.error().message;
            return fail(located(g.where, why.starts_with(field + ": ") ? std::string() : field, why));
        }
        Garment& made = world.registry.get<Garment>(*garment);
        made.config.warp_solve = g.warp_solve;
        if (made.config.max_distance_share > 0 && made.config.max_distance_on_skin && made.body.rest_on_skin.empty())
            world.warnings.push_back(field + ".max_distance_on_skin: the character has no skin of trunk and legs to bind the spheres to; "
                                             "the anchor carries them");
        world.garments.push_back(*garment);
        // A mesh of the character's own file that is now cloth is not drawn skinned too.
        if (auto* skin = world.registry.try_get<SkinnedMesh>(body); skin && skin->mesh)
            for (const std::size_t k : own) hide_submesh(*skin, k);
    }
    // A garment simulated over one modelled into the file: the modelled one is not drawn.
    for (std::size_t i = 0; i < scene.characters.size(); ++i) {
        const CharacterDescription& c = scene.characters[i];
        const bool dressed = std::any_of(scene.garments.begin(), scene.garments.end(),
                                         [&](const GarmentDescription& g) { return g.character == static_cast<int>(i); });
        auto* skin = world.registry.try_get<SkinnedMesh>(world.characters[i]);
        if (!dressed || !c.hide_modelled_garments || skin == nullptr || !skin->mesh) continue;
        for (const LeftOutMesh& part : loaded.at({c.file, c.thicken_thin_trunk_m}).body.left_out)
            if (part.garment) hide_submesh(*skin, part.mesh);
    }
    settle_garments(world);
    world.watch = GarmentWatch(world.registry, world.garments, options.skin_penetration ? options.skin_penetration_every : 0);
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
        world.scheduler.add(make_garment_surface_system());
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
