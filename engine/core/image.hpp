// An RGBA8 picture in memory: a frame read back from the renderer, a garment's base-colour
// texture. Plain data; PNG input and output live with their users (engine/render/image.hpp,
// engine/assets/garment_file.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

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

}  // namespace drape
