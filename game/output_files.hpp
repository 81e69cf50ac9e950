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
#include <string>
#include <string_view>
#include <vector>

#include "drape/engine/core/error.hpp"

namespace drape {

/// Ok when `file` does not exist, or exists and `overwrite` is set; else one line naming
/// `option`: "--stats: stats.json already exists (add --overwrite to replace it)".
[[nodiscard]] Result<void> check_new_file(std::string_view option, const std::filesystem::path& file, bool overwrite);

/// A hidden sibling of `file` to write first: "dir/.name.partial.ext" (the extension is
/// kept so that tools that choose a format by it, like ffmpeg, still do).
[[nodiscard]] std::filesystem::path partial_path(const std::filesystem::path& file);

/// Renames the complete `partial` onto `file` (replacing it); removes `partial` on failure.
[[nodiscard]] Result<void> commit_partial(const std::filesystem::path& partial, const std::filesystem::path& file);

/// A path under `folder` named stem + extension, or stem-2 + extension, stem-3 ..., the
/// first that does not exist yet: the outputs Drape names itself never overwrite anything.
[[nodiscard]] std::filesystem::path fresh_path(const std::filesystem::path& folder, const std::string& stem,
                                               const std::string& extension);

/// Name of frame `index` in a frame folder (`drape play --out DIR`): "frame_00000.png".
[[nodiscard]] std::string frame_file_name(int index);

/// The frame files (frame_NNNNN.png) in `folder`, in no particular order; none when it
/// cannot be read.
[[nodiscard]] std::vector<std::filesystem::path> frame_files(const std::filesystem::path& folder);

/// Removes the frame files of `folder` numbered `count` and above (an older, longer run's),
/// so that it holds one run's frames.
void remove_frames_from(const std::filesystem::path& folder, int count);

/// Everything a run creates (folders, frames), removed again unless the run completes
/// (keep()): a run that fails leaves nothing behind and never removes what existed
/// before it.
class CreatedOutputs {
public:
    CreatedOutputs() = default;
    CreatedOutputs(const CreatedOutputs&) = delete;
    CreatedOutputs& operator=(const CreatedOutputs&) = delete;
    ~CreatedOutputs();

    /// Creates `folder` and its missing parents, remembering each one it made.
    [[nodiscard]] Result<void> create_folder(const std::filesystem::path& folder);
    /// Remembers a file the run is about to write.
    void add_file(const std::filesystem::path& file) { m_files.push_back(file); }
    /// The run completed: keep everything.
    void keep() { m_kept = true; }

private:
    std::vector<std::filesystem::path> m_files, m_folders;
    bool m_kept = false;
};

}  // namespace drape
