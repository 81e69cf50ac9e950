// `drape export-garment [--character FILE] [--garment skirt|dress] --out FILE.gltf`: writes a
// built-in garment, as it is put on the character (before it settles), as a glTF mesh with
// its pattern (UVs) and its pins painted (COLOR_0): a file `drape play --garment FILE` or a
// scene's garment "file" turns back into the same cloth (docs/garments.md). Never
// overwrites a file.
#include <cstdio>
#include <memory>
#include <string>

#include "drape/game/commands.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/world.hpp"
#include "drape/systems/cloth/garment_from_mesh.hpp"

namespace drape {

void add_export_garment_command(CLI::App& app) {
    struct Options {
        std::string character, garment = "skirt", out, clip;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("export-garment", "Write a built-in garment as a glTF mesh (UVs, pins painted) to start your own from");
    command->add_option("--character", o->character, "Character file (default: the sample scene's avatar)")->check(not_empty());
    command->add_option("--garment", o->garment, "The built-in garment")->check(one_of({"skirt", "dress"}))->capture_default_str();
    command->add_option("--clip", o->clip, "Clip whose first pose the garment is put on in (default: the one play chooses)")->check(not_empty());
    command->add_option("--out", o->out, "The .gltf or .glb file to write (never overwritten)")->required()->check(not_empty());
    command->callback([o] {
        auto error = [](const std::string& message) { command_error("export-garment", message); };
        SceneDescription scene = sample_scene();
        if (!o->character.empty()) use_character_file(scene, o->character);
        if (!o->clip.empty()) scene.characters.at(0).clip = o->clip;
        scene.garments.resize(1);
        scene.garments[0] = GarmentDescription{};
        scene.garments[0].type = o->garment == "dress" ? GarmentType::dress : GarmentType::skirt;
        scene.solver.settle_s = 0;  // the garment as it is put on
        auto world = build_world(scene, {});
        if (!world) return error(world.error().message);
        GarmentMeshAsset mesh = garment_as_mesh(world->registry, world->garments.at(0));
        mesh.name = o->garment == "dress" ? "Dress" : "Skirt";
        if (auto ok = write_garment_mesh(o->out, mesh); !ok) return error("--out: " + ok.error().message);
        std::printf("drape export-garment: wrote %s (%s, %zu vertices, %zu triangles)\n", o->out.c_str(), mesh.name.c_str(),
                    mesh.vertex_count(), mesh.indices.size() / 3);
    });
}

}  // namespace drape
