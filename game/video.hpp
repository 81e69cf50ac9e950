// Video output: frames piped to ffmpeg as raw RGBA, encoded to H.264 (yuv420p, plays
// everywhere). ffmpeg is a run-time dependency only; without it `open` says so.
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "drape/engine/core/error.hpp"

namespace drape {

struct Image;

/// The ffmpeg executable on PATH, if any.
[[nodiscard]] std::optional<std::filesystem::path> find_ffmpeg();

class VideoWriter {
public:
    /// Starts ffmpeg writing `file` (overwritten: the caller chose the name).
    [[nodiscard]] static Result<VideoWriter> open(const std::filesystem::path& file, int width, int height, double fps);

    VideoWriter(VideoWriter&&) noexcept = default;
    VideoWriter& operator=(VideoWriter&&) noexcept = default;
    /// Closes the pipe if close() was not called; the file is then removed (incomplete).
    ~VideoWriter();

    /// Sends one frame; it must have the size given to open().
    [[nodiscard]] Result<void> write(const Image& frame);
    /// Finishes the file and checks ffmpeg's exit status. On error the file is removed.
    [[nodiscard]] Result<void> close();

    [[nodiscard]] int frames() const noexcept { return m_frames; }
    [[nodiscard]] const std::filesystem::path& file() const noexcept { return m_file; }

private:
    struct PipeCloser {
        void operator()(std::FILE* f) const noexcept;
    };
    VideoWriter() = default;
    std::unique_ptr<std::FILE, PipeCloser> m_pipe;
    std::filesystem::path m_file;
    int m_width = 0, m_height = 0, m_frames = 0;
};

}  // namespace drape
