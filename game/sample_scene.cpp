// The sample scene; see sample_scene.hpp.
#include "drape/game/sample_scene.hpp"

#include "drape/game/asset_paths.hpp"

namespace drape {

void use_character_file(SceneDescription& scene, const std::filesystem::path& file) {
    if (scene.characters.empty()) scene.characters.emplace_back();
    scene.characters[0].file = file;
    scene.characters[0].clip.clear();
    scene.characters[0].where = {};
    std::erase_if(scene.colliders, [](const ColliderOverride& c) { return c.character == 0; });
}

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

}  // namespace drape
