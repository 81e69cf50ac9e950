// A game dressing a character in a skirt through the installed package: the code of
// README.md's "Use it in your CMake project", with the contract checked at the end.
//   my_game CHARACTER_FILE
#include <cstdio>

#include <drape/game/contract.hpp>
#include <drape/game/world.hpp>
#include <drape/systems/cloth/garment_config.hpp>
#include <drape/systems/cloth/garment_parameters.hpp>

int main(int argc, char** argv) {
    if (argc < 2) return std::fprintf(stderr, "usage: my_game CHARACTER_FILE\n"), 2;
    // --- README: begin
    drape::SceneDescription scene;                  // or drape::load_scene_file("scene.json")
    scene.characters.push_back({.file = argv[1]});  // .glb, .gltf, .fbx, ...: its walk plays
    scene.garments.push_back({.type = drape::GarmentType::skirt});
    auto world = drape::build_world(scene, {});     // headless
    if (!world) return std::fprintf(stderr, "%s\n", world.error().message.c_str()), 1;

    const drape::Entity skirt = world->garments[0];
    auto denim = drape::material_preset("denim");
    if (auto ok = drape::set_garment_material(world->registry, skirt, *denim); !ok) return 1;
    for (int frame = 0; frame < 60; ++frame) drape::step_world(*world, 1.0 / 60.0);

    const drape::GarmentStats stats = drape::run_stats(*world).garments[0];
    std::printf("%s\n", drape::garment_verdict("skirt", stats).c_str());
    // --- README: end
    // The contract asked of any character: largest strain at most 20 %, nothing non-finite.
    const bool ok = stats.strain_max <= 0.20 && stats.nonfinite == 0 && !drape::has_nonfinite(*world);
    return ok ? 0 : 1;
}
