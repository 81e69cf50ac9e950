// How Drape's commands write files: never over a file the user did not ask to replace,
// and never leave half a file behind.
//
// Rule: a file named on the command line (`--stats`, `--trace`, `--video`, `--out` frames,
// `make-avatar --out`) that already exists is refused unless `--overwrite` is given;
// outputs Drape names itself (out/sample.mp4, out/sample-2.mp4, ...) always take a fresh
// name. Files are written under a hidden partial name next to the target and renamed onto
// it once complete, so a failed or interrupted run leaves the old file (or nothing).
#pragma once

#include <filesystem>
#include <string_view>

#include "engine/core/error.hpp"

namespace drape {

/// Ok when `file` does not exist, or exists and `overwrite` is set; else one line naming
/// `option`: "--stats: stats.json already exists (add --overwrite to replace it)".
[[nodiscard]] Result<void> check_new_file(std::string_view option, const std::filesystem::path& file, bool overwrite);

/// A hidden sibling of `file` to write first: "dir/.name.partial.ext" (the extension is
/// kept so that tools that choose a format by it, like ffmpeg, still do).
[[nodiscard]] std::filesystem::path partial_path(const std::filesystem::path& file);

/// Renames the complete `partial` onto `file` (replacing it); removes `partial` on failure.
[[nodiscard]] Result<void> commit_partial(const std::filesystem::path& partial, const std::filesystem::path& file);

}  // namespace drape
