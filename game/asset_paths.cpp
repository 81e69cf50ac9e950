// Asset lookup; see asset_paths.hpp.
#include "drape/game/asset_paths.hpp"

#include <cstdlib>
#include <system_error>

namespace drape {

namespace fs = std::filesystem;

fs::path asset_dir() {
    std::error_code ec;
    auto has_avatar = [&](const fs::path& dir) { return fs::is_regular_file(dir / "avatar.glb", ec); };
    if (const char* env = std::getenv("DRAPE_ASSETS"); env != nullptr && *env != '\0') return fs::path(env);
    if (has_avatar("assets")) return fs::absolute("assets", ec);
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec)
        for (const fs::path& candidate : {exe.parent_path() / "../assets", exe.parent_path() / "../share/drape/assets"})
            if (has_avatar(candidate)) return candidate.lexically_normal();
#ifdef DRAPE_SOURCE_ASSETS
    return fs::path(DRAPE_SOURCE_ASSETS);
#else
    return fs::absolute("assets", ec);
#endif
}

fs::path default_avatar_path() { return asset_dir() / "avatar.glb"; }

}  // namespace drape
