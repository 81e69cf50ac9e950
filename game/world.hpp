// A running world built from a scene description: Registry + Scheduler + systems, the
// entities of the scene, and optionally a Renderer. Used by `drape play`, the tests and
// the benchmarks, so that all three run exactly the same scene.
//
//   auto scene = drape::load_scene_file("x.json");        // or drape::sample_scene()
//   auto world = drape::build_world(*scene, {});           // headless
//   for (int i = 0; i < 600; ++i) drape::step_world(*world, 1.0 / 60.0);
//
// Putting the garments on (docs/characters.md): build_world builds each garment around its
// body in the pose the clip starts in and lets it settle there for `solver.settle_s`, the
// bodies held still, before returning; those steps are not frames (nothing drawn, not in the
// stats or the profile).
//
// Systems, in phase order (engine/core/scheduler.hpp): the character systems (animation,
// colliders), then the teleport guard (systems/teleport_guard_system.hpp), then the cloth
// systems, then, only when rendering, the skinning system (the mesh, once per frame) and
// the render system. A headless world skins no mesh vertex.
//
// Robustness (method-independent, docs/scenes.md "solver"):
// - hitches: step_world clamps a frame time to `solver.max_frame_dt_s` before the
//   scheduler's own step cap (`max_steps_per_frame`) drops what is left;
// - time scale: `solver.time_scale`, changeable while running (set_time_scale);
// - teleports: when a character's root moves further than `solver.teleport_threshold_m`
//   within one fixed step (a game moving its Transform, a clip jumping), every garment it
//   wears is reset to its rest shape around the body at the new place (reset_garment);
//   `reset_garments` does the same on request (the window's reset key).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"
#include "drape/game/scene_description.hpp"
#include "drape/game/stats.hpp"
#include "drape/systems/teleport_guard_system.hpp"

namespace drape {

class Renderer;

/// How to build a world (what the scene file does not say).
struct WorldOptions {
    bool render = false;             ///< Create a Renderer and the render system (needs the render module).
    bool window = false;             ///< Render into an X11 window instead of off-screen.
    int width = 1280, height = 720;  ///< Frame size, px.
    bool profile = true;             ///< Time every system run (the frame budget table).
    /// Folder where fitted bodies are kept between runs (systems/character/body_cache.hpp); empty: the
    /// folder DRAPE_BODY_CACHE names, or none.
    std::filesystem::path body_cache;
    bool skin_penetration = false;   ///< Measure cloth behind the skin mesh (game/skin_penetration.hpp; costs a skinning and a search per measured frame) ...
    int skin_penetration_every = 1;  ///< ... after every this many frames (1: every frame).
};

/// A running scene: its description, registry, scheduler with the systems, its entities,
/// and the renderer when it renders.
struct World {
    SceneDescription scene;
    Registry registry;
    Scheduler scheduler;
    std::vector<Entity> characters;      ///< Scene order.
    std::vector<Entity> garments;        ///< Scene order.
    std::shared_ptr<Renderer> renderer;  ///< Null when headless.
    GarmentWatch watch;                  ///< Worst strain, penetration, non-finite values.
    std::shared_ptr<TeleportLog> teleports = std::make_shared<TeleportLog>();
    std::shared_ptr<void> thread_limit;  ///< Keeps solver.threads in force while the world lives.
    std::vector<std::string> warnings;   ///< What loading accepted with a remark (CharacterAsset::warnings), one line each.
};

/// Loads the characters, fits and overrides their colliders, dresses them, adds the
/// systems. Errors name the scene file, field and reason (e.g. a bone that does not exist).
[[nodiscard]] Result<World> build_world(const SceneDescription& scene, const WorldOptions& options);

/// One frame: clamps the frame time (solver.max_frame_dt_s), ticks the scheduler,
/// samples the garments for the stats. Errors only on a bad frame time.
Result<FrameReport> step_world(World& world, double frame_dt_s);

/// Resets every garment to its rest shape around its body where the body is now.
void reset_garments(World& world);

/// Switches every garment to a cloth model (the window's model key); the scene
/// description follows.
void set_garment_model(World& world, ClothModel model);

/// Changes the simulated seconds per wall-clock second; the error names the value.
[[nodiscard]] Result<void> set_time_scale(World& world, double scale);

/// Run statistics so far (the --stats file).
[[nodiscard]] RunStats run_stats(const World& world);

/// True when a garment particle, velocity, skinning matrix or skinned body vertex is not finite.
[[nodiscard]] bool has_nonfinite(const World& world);

/// Whether this build has the render module.
[[nodiscard]] bool render_available() noexcept;

}  // namespace drape
