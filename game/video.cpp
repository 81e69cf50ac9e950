#include "drape/game/video.hpp"

#include <csignal>
#include <cstdlib>
#include <string_view>
#include <sys/wait.h>
#include <unistd.h>

#include "drape/engine/render/image.hpp"

namespace drape {

std::optional<std::filesystem::path> find_ffmpeg() {
    const char* path = std::getenv("PATH");
    if (path == nullptr) return std::nullopt;
    std::string_view rest(path);
    while (!rest.empty()) {
        const std::size_t colon = rest.find(':');
        const std::string_view folder = rest.substr(0, colon);
        rest = colon == std::string_view::npos ? std::string_view{} : rest.substr(colon + 1);
        if (folder.empty()) continue;
        std::filesystem::path candidate = std::filesystem::path(folder) / "ffmpeg";
        if (::access(candidate.c_str(), X_OK) == 0) return candidate;
    }
    return std::nullopt;
}

namespace {
// 'text' for /bin/sh, with single quotes escaped.
std::string shell_quote(const std::string& text) {
    std::string out = "'";
    for (char c : text) {
        if (c == '\'')
            out += "'\\''";
        else
            out += c;
    }
    return out + "'";
}
}  // namespace

void VideoWriter::PipeCloser::operator()(std::FILE* f) const noexcept {
    if (f != nullptr) ::pclose(f);
}

Result<VideoWriter> VideoWriter::open(const std::filesystem::path& file, int width, int height, double fps) {
    const auto ffmpeg = find_ffmpeg();
    if (!ffmpeg)
        return fail(file.string() + ": cannot write video: ffmpeg is not installed (apt-get install ffmpeg), "
                                    "or write PNG frames with --out DIR");
    if (width <= 0 || height <= 0 || !(fps > 0)) return fail(file.string() + ": bad video size or frame rate");
    std::error_code ec;
    if (std::filesystem::is_directory(file, ec)) return fail(file.string() + ": is a folder, not a video file");
    const std::filesystem::path folder = file.parent_path();
    if (!folder.empty() && !std::filesystem::is_directory(folder, ec))
        return fail(file.string() + ": folder " + folder.string() + " does not exist");
    // A dead ffmpeg must turn into a write error, not kill Drape with SIGPIPE.
    std::signal(SIGPIPE, SIG_IGN);
    const std::string size = std::to_string(width) + "x" + std::to_string(height);
    // ffmpeg runs in its own session when setsid exists: Ctrl-C in the terminal then stops
    // Drape between frames (which closes the video properly), not ffmpeg mid-stream.
    const bool setsid = ::access("/usr/bin/setsid", X_OK) == 0;
    const std::string command = std::string(setsid ? "exec /usr/bin/setsid " : "exec ") + shell_quote(ffmpeg->string()) +
                                " -nostdin -hide_banner -loglevel error -y -f rawvideo -pixel_format rgba -video_size " + size +
                                " -framerate " + std::to_string(fps) +
                                " -i - -vf " + shell_quote("scale=trunc(iw/2)*2:trunc(ih/2)*2") + " -c:v libx264 -preset veryfast -crf 20"
                                " -pix_fmt yuv420p -movflags +faststart " +
                                shell_quote(file.string());
    std::FILE* pipe = ::popen(command.c_str(), "w");
    if (pipe == nullptr) return fail(file.string() + ": cannot start ffmpeg");
    VideoWriter w;
    w.m_pipe.reset(pipe);
    w.m_file = file;
    w.m_width = width;
    w.m_height = height;
    return w;
}

VideoWriter::~VideoWriter() {
    if (m_pipe) {
        m_pipe.reset();
        std::error_code ec;
        std::filesystem::remove(m_file, ec);
    }
}

Result<void> VideoWriter::write(const Image& frame) {
    if (!m_pipe) return fail(m_file.string() + ": video already closed");
    if (frame.width != m_width || frame.height != m_height)
        return fail(m_file.string() + ": frame is " + std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                    ", video is " + std::to_string(m_width) + "x" + std::to_string(m_height));
    const std::size_t bytes = frame.rgba.size();
    if (std::fwrite(frame.rgba.data(), 1, bytes, m_pipe.get()) != bytes) {
        m_pipe.reset();
        std::error_code ec;
        std::filesystem::remove(m_file, ec);
        return fail(m_file.string() + ": ffmpeg stopped accepting frames (see its message above)");
    }
    ++m_frames;
    return {};
}

Result<void> VideoWriter::close() {
    if (!m_pipe) return fail(m_file.string() + ": video already closed");
    const int status = ::pclose(m_pipe.release());
    if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::error_code ec;
        std::filesystem::remove(m_file, ec);
        return fail(m_file.string() + ": ffmpeg failed (exit status " +
                    std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
    }
    return {};
}

}  // namespace drape
