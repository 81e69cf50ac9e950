// `drape make-avatar [--out FILE] [--overwrite]`: writes Drape's default avatar
// (game/avatar_generator.hpp). An existing FILE with the same bytes is left as it is; a
// different one is replaced only with --overwrite (game/output_files.hpp).
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "drape/game/avatar_generator.hpp"
#include "drape/game/commands.hpp"
#include "drape/game/output_files.hpp"

namespace drape {

namespace {

bool same_bytes(const std::filesystem::path& file, const std::vector<std::uint8_t>& bytes) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return false;
    const std::vector<char> old((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return old.size() == bytes.size() && std::equal(old.begin(), old.end(), bytes.begin(), [](char a, std::uint8_t b) {
               return static_cast<std::uint8_t>(a) == b;
           });
}

}  // namespace

void add_make_avatar_command(CLI::App& app) {
    struct Options {
        std::string out = "assets/avatar.glb";
        bool overwrite = false;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("make-avatar", "Generate the default avatar (mesh, skeleton, walk and idle clips) as binary glTF");
    command->add_option("--out", o->out, "Where to write the .glb file")->capture_default_str();
    command->add_flag("--overwrite", o->overwrite, "Replace FILE if it exists with other contents (else: an error)");
    command->callback([o] {
        auto error = [](const std::string& message) { command_error("make-avatar", message); };
        const std::filesystem::path out = o->out;
        const AvatarModel model = make_default_avatar();
        auto bytes = avatar_glb(model);
        if (!bytes) return error(bytes.error().message);
        std::error_code ec;
        if (std::filesystem::is_regular_file(out, ec) && same_bytes(out, *bytes)) {
            std::printf("drape make-avatar: %s is up to date\n", out.c_str());
            return;
        }
        if (auto ok = check_new_file("--out", out, o->overwrite); !ok) return error(ok.error().message);
        const std::filesystem::path folder = out.parent_path();
        if (!folder.empty() && !std::filesystem::is_directory(folder, ec))
            return error("--out: folder " + folder.string() + " does not exist");
        const std::filesystem::path partial = partial_path(out);
        {
            std::ofstream file(partial, std::ios::binary | std::ios::trunc);
            file.write(reinterpret_cast<const char*>(bytes->data()), static_cast<std::streamsize>(bytes->size()));
            file.close();
            if (!file) {
                std::filesystem::remove(partial, ec);
                return error("--out: " + out.string() + ": cannot write");
            }
        }
        if (auto ok = commit_partial(partial, out); !ok) return error("--out: " + ok.error().message);
        std::printf("drape make-avatar: wrote %s (%zu vertices, %zu triangles, %zu bones", out.c_str(),
                    std::size_t(model.positions.cols()), model.triangle_count(), model.bones.size());
        for (const AvatarClip& clip : model.clips) std::printf(", %s %.2f s", clip.name.c_str(), clip.duration_s());
        std::puts(")");
    });
}

}  // namespace drape
