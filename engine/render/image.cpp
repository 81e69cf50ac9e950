#include "drape/engine/render/image.hpp"

#include <cerrno>
#include <cstring>
#include <string>

#include <stb/stb_image_write.h>  // compiled in Debian's libstb (Drape::stb)

namespace drape {

Result<void> write_png(const Image& image, const std::filesystem::path& path) {
    const std::string name = path.string();
    if (image.empty())
        return fail(name + ": cannot write an empty image (" + std::to_string(image.width) + "x" +
                    std::to_string(image.height) + ")");
    const std::size_t expected = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4;
    if (image.rgba.size() != expected)
        return fail(name + ": image holds " + std::to_string(image.rgba.size()) + " bytes, expected " +
                    std::to_string(expected) + " for " + std::to_string(image.width) + "x" +
                    std::to_string(image.height) + " RGBA8");
    if (path.has_parent_path()) {
        std::error_code ec;
        std::filesystem::create_directories(path.parent_path(), ec);
        if (ec) return fail(name + ": cannot create folder " + path.parent_path().string() + ": " + ec.message());
    }
    errno = 0;
    if (stbi_write_png(name.c_str(), image.width, image.height, 4, image.rgba.data(), image.width * 4) == 0)
        return fail(name + ": cannot write PNG" + (errno != 0 ? std::string(": ") + std::strerror(errno) : std::string()));
    return {};
}

}  // namespace drape
