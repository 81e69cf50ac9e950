// See output_files.hpp.
#include "drape/game/output_files.hpp"

// GCC 12 with the sanitizers warns inside libstdc++'s <regex> (the std::function in its
// automaton's states: -Wmaybe-uninitialized, a false positive); the standard headers are
// read with that warning off.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <cstdio>
#include <regex>
#include <string>
#pragma GCC diagnostic pop

namespace drape {

namespace fs = std::filesystem;

Result<void> check_new_file(std::string_view option, const fs::path& file, bool overwrite) {
    std::error_code ec;
    const fs::file_status status = fs::symlink_status(file, ec);
    if (!fs::exists(status)) return {};
    if (fs::is_directory(status)) return fail(std::string(option) + ": " + file.string() + " is a folder");
    if (!overwrite) return fail(std::string(option) + ": " + file.string() + " already exists (add --overwrite to replace it)");
    return {};
}

fs::path partial_path(const fs::path& file) {
    std::string name = file.stem().string();
    name.insert(0, 1, '.');
    name += ".partial";
    name += file.extension().string();
    return file.parent_path() / name;
}

Result<void> commit_partial(const fs::path& partial, const fs::path& file) {
    std::error_code ec;
    fs::rename(partial, file, ec);
    if (!ec) return {};
    const std::string why = ec.message();
    fs::remove(partial, ec);
    return fail(file.string() + ": cannot write: " + why);
}

fs::path fresh_path(const fs::path& folder, const std::string& stem, const std::string& extension) {
    std::error_code ec;
    for (int n = 1;; ++n) {
        fs::path p = folder / (n == 1 ? stem + extension : stem + "-" + std::to_string(n) + extension);
        if (!fs::exists(p, ec)) return p;
    }
}

std::string frame_file_name(int index) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", index);
    return name;
}

namespace {

bool is_frame_file(const fs::path& file) {
    static const std::regex name(R"(frame_\d{5}\.png)");
    return std::regex_match(file.filename().string(), name);
}

}  // namespace

std::vector<fs::path> frame_files(const fs::path& folder) {
    std::vector<fs::path> out;
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec))
        if (is_frame_file(it->path())) out.push_back(it->path());
    return out;
}

void remove_frames_from(const fs::path& folder, int count) {
    for (const fs::path& f : frame_files(folder))
        if (std::stoi(f.filename().string().substr(6, 5)) >= count) {
            std::error_code ec;
            fs::remove(f, ec);
        }
}

CreatedOutputs::~CreatedOutputs() {
    if (m_kept) return;
    std::error_code ec;
    for (const fs::path& f : m_files) fs::remove(f, ec);
    for (auto it = m_folders.rbegin(); it != m_folders.rend(); ++it) fs::remove(*it, ec);  // only when empty
}

Result<void> CreatedOutputs::create_folder(const fs::path& folder) {
    std::vector<fs::path> missing;
    std::error_code ec;
    for (fs::path p = folder; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
        missing.push_back(p);
        if (p == p.parent_path()) break;
    }
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
        if (!fs::create_directory(*it, ec) && ec) return fail(it->string() + ": cannot create the folder: " + ec.message());
        m_folders.push_back(*it);
    }
    return {};
}

}  // namespace drape
