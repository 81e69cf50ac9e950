// The sample scene: Drape's default avatar walking in place in the paper's skirt, what
// `drape play` plays with no scene named.
#pragma once

#include "drape/game/scene_description.hpp"

namespace drape {

/// The sample scene: the default avatar walking in place in a skirt. The same as
/// assets/scenes/sample.json.
[[nodiscard]] SceneDescription sample_scene();

}  // namespace drape
