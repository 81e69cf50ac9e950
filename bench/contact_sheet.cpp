#include "bench/contact_sheet.hpp"

#ifdef DRAPE_HAVE_RENDER
#include <algorithm>

namespace drape::bench {

void put_tile(Image& sheet, const Image& source, int x0, int y0, int scale) {
    const int height = std::min(source.height / scale, sheet.height - y0);
    const int width = std::min(source.width / scale, sheet.width - x0);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int channel = 0; channel < 4; ++channel) {
                int sum = 0;
                for (int dy = 0; dy < scale; ++dy)
                    for (int dx = 0; dx < scale; ++dx) sum += source.at(x * scale + dx, y * scale + dy)[channel];
                const std::size_t at = (static_cast<std::size_t>(y0 + y) * static_cast<std::size_t>(sheet.width) +
                                        static_cast<std::size_t>(x0 + x)) * 4 + static_cast<std::size_t>(channel);
                sheet.rgba[at] = static_cast<std::uint8_t>((sum + scale * scale / 2) / (scale * scale));
            }
}

Image blank_sheet(int columns, int rows, int tile_width, int tile_height) {
    Image sheet;
    sheet.width = columns * (tile_width + 4) - 4;
    sheet.height = rows * (tile_height + 4) - 4;
    sheet.rgba.assign(static_cast<std::size_t>(sheet.width) * static_cast<std::size_t>(sheet.height) * 4, 255);
    return sheet;
}

}  // namespace drape::bench
#endif
