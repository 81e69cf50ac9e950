// The worlds the benchmarks run: the default avatar walking in place with a garment, built
// through the game's scene description exactly as `drape play` builds its scene.
#pragma once

#include <filesystem>
#include <vector>

#include "drape/components/garment.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/game/world.hpp"

namespace drape::bench {

/// What to build.
struct WorldSpec {
    int walkers = 1;                                   ///< Characters, in a grid 1.5 m apart.
    GarmentType garment = GarmentType::skirt;
    ClothModel model = ClothModel::simplified;
    ClothIntegrator integrator = ClothIntegrator::shipped;
    WarpSolve warp_solve = WarpSolve::rounds;          ///< The shipped integrator's warp springs.
    CollisionMode collision = CollisionMode::candidate_lists;
    int particles = 0;                                 ///< 0: the builder's default.
    int substeps = 0;                                  ///< 0: the cloth's stability rule.
    double fixed_dt_s = 1.0 / 60.0;                    ///< Simulated time per fixed step.
    double time_scale = 1;
    int threads = 1;
    bool profile = true;                               ///< Time every system run.
    bool in_place = true;                              ///< false: root motion moves the walkers.
    double phase_step_s = 0;                           ///< Walker i starts i x this into its clip (0: all in step).
    bool render = false;                               ///< Off-screen renderer + render system (1280x720).
};

/// The scene description of a spec (default avatar, its walk, in place).
[[nodiscard]] SceneDescription scene_for(const WorldSpec& spec);

/// Builds a headless world; the error says what is missing (e.g. the avatar file).
[[nodiscard]] Result<World> build_bench_world(const WorldSpec& spec);

/// The shared third-party characters next to the project: ../shared/assets/characters from
/// the source tree's root (or from the working folder when the source tree is gone).
[[nodiscard]] std::filesystem::path shared_characters_dir();

/// The first garment of a world.
[[nodiscard]] Garment& first_garment(World& world);

}  // namespace drape::bench
