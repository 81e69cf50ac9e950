// See output_files.hpp.
#include "game/output_files.hpp"

#include <string>

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

}  // namespace drape
