// Dressing any character in a skirt, through Drape's components and systems directly.
//
//   build/drape_dress_example [CHARACTER_FILE] [CLIP] [FRAMES]
//   build/drape_dress_example ../shared/assets/characters/male_casual/Male_Casual.fbx "HumanArmature|Man_Walk"
//
// The same scene through a file is `drape play --scene`, and through the command line
// `drape play --character FILE --garment skirt`. This file shows the five steps a game
// takes; every step that can fail returns a Result whose message names the file or field.
#include <cstdio>
#include <string>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/engine/assets/character_import.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"
#include "drape/game/asset_paths.hpp"
#include "drape/systems/character_systems.hpp"
#include "drape/systems/character/spawn.hpp"
#include "drape/systems/cloth_systems.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_quality.hpp"

namespace {

int fail_with(const std::string& message) {
    std::fprintf(stderr, "drape_dress_example: %s\n", message.c_str());
    return 1;
}

// Free particles inside an ellipsoid of their body (the collision must leave none,
// method §5; pinned particles follow the skin and may sit inside).
int particles_inside(drape::Registry& registry, const drape::Garment& garment) {
    int inside = 0;
    for (Eigen::Index i = 0; i < garment.state.x.cols(); ++i) {
        if (garment.state.inv_mass[i] == 0) continue;
        bool in = false;
        registry.view<drape::EllipsoidCollider>().each([&](drape::Entity, drape::EllipsoidCollider& c) {
            if (c.character == garment.body.character && (c.world.inverse() * garment.state.x.col(i)).norm() < 0.99f) in = true;
        });
        inside += in ? 1 : 0;
    }
    return inside;
}

}  // namespace

int main(int argc, char** argv) {
    const std::string file = argc > 1 && *argv[1] != 0 ? argv[1] : drape::default_avatar_path().string();
    const std::string clip = argc > 2 ? argv[2] : "";
    const int frames = argc > 3 ? std::atoi(argv[3]) : 300;
    if (frames <= 0) return fail_with("FRAMES must be a positive integer");

    // 1. Import: skeleton, skin, clips in metres and seconds; then the body: ellipsoid
    //    colliders fitted to the bones from the skin weights (method §2).
    auto asset = drape::import_character(file);
    if (!asset) return fail_with(asset.error().message);
    auto body = drape::fit_character_body(**asset);
    if (!body) return fail_with(body.error().message);

    // 2. Spawn: the character entity and one entity per collider, posed, skinned and
    //    placed: valid before the first step.
    drape::Registry registry;
    drape::SpawnOptions spawn;
    spawn.clip = clip;  // empty: the importer's first clip
    auto character = drape::spawn_character(registry, *asset, *body, spawn);
    if (!character) return fail_with(character.error().message);

    // 3. Systems: animation, colliders, then the cloth's three systems.
    drape::Scheduler scheduler;
    drape::add_character_systems(scheduler);
    drape::add_cloth_systems(scheduler);

    // 4. The skirt: a cone hung from the fitted hip ellipsoids, top row pinned to the skin.
    const drape::TubeParams skirt = drape::TubeParams::skirt();  // 27 x 31 = 837 particles, the paper's skirt
    auto garment = drape::attach_skirt(registry, *character, skirt);
    if (!garment) return fail_with(garment.error().message);

    // 5. Play: one tick per frame; the scheduler takes fixed steps and substeps.
    for (int frame = 0; frame < frames; ++frame)
        if (auto report = scheduler.tick(registry, 1.0 / 60.0); !report) return fail_with(report.error().message);

    const drape::Garment& g = registry.get<drape::Garment>(*garment);
    std::fputs(scheduler.profiler().table().c_str(), stdout);
    const bool finite = g.state.x.allFinite() && g.state.v.allFinite();
    const int inside = particles_inside(registry, g);
    std::printf("%s: %lld particles, lowest at %.3f m, max strain %.3f, %d inside an ellipsoid, %s\n", file.c_str(),
                static_cast<long long>(g.state.x.cols()), finite ? double(g.state.x.row(1).minCoeff()) : 0.0, double(measure_garment(registry, g).strain_max),
                inside, finite ? "all finite" : "NON-FINITE VALUES");
    return finite && inside == 0 ? 0 : 1;
}
