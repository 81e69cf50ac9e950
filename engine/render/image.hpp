// PNG output of an image (a frame read back from the renderer).
#pragma once

#include <filesystem>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/image.hpp"

namespace drape {

/// Writes an image as PNG; the error names the path and the reason.
[[nodiscard]] Result<void> write_png(const Image& image, const std::filesystem::path& path);

}  // namespace drape
