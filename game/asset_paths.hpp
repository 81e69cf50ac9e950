// Where Drape finds its assets (the default avatar, the example scenes) when run from the
// project folder, from an install, or from anywhere with the source tree still in place.
#pragma once

#include <filesystem>

namespace drape {

/// The project's asset folder: $DRAPE_ASSETS, ./assets, next to the executable
/// (../assets, ../share/drape/assets) or the source tree's assets/.
[[nodiscard]] std::filesystem::path asset_dir();

/// The default avatar file (assets/avatar.glb).
[[nodiscard]] std::filesystem::path default_avatar_path();

}  // namespace drape
