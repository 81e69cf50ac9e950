// Contact sheets: rendered frames put side by side in one PNG, shared by the benchmarks that
// show what a user sees (quality, motions).
#pragma once

#ifdef DRAPE_HAVE_RENDER
#include "drape/engine/render/image.hpp"

namespace drape::bench {

/// Averages `scale` x `scale` blocks of `source` into the tile at (x0, y0) of `sheet` (what
/// would fall outside the sheet is left out).
void put_tile(Image& sheet, const Image& source, int x0, int y0, int scale);

/// A white sheet of `columns` x `rows` tiles of `tile_width` x `tile_height`, 4 px apart.
[[nodiscard]] Image blank_sheet(int columns, int rows, int tile_width, int tile_height);

}  // namespace drape::bench
#endif
