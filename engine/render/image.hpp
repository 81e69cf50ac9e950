// A CPU image read back from the renderer, and PNG output.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "drape/engine/core/error.hpp"

namespace drape {

/// RGBA8 pixels, top row first, rows tightly packed (stride = 4 * width).
struct Image {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgba;

    [[nodiscard]] bool empty() const noexcept { return width <= 0 || height <= 0; }
    /// Pointer to the 4 bytes of pixel (x, y), y = 0 at the top. Unchecked.
    [[nodiscard]] const std::uint8_t* at(int x, int y) const noexcept {
        return rgba.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 4;
    }
};

/// Writes an image as PNG; the error names the path and the reason.
[[nodiscard]] Result<void> write_png(const Image& image, const std::filesystem::path& path);

}  // namespace drape
