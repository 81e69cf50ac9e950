// The sample scene; see sample_scene.hpp.
#include "drape/game/sample_scene.hpp"

#include "drape/game/asset_paths.hpp"

namespace drape {

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
