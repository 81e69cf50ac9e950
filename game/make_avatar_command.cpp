// `drape make-avatar [--out FILE]`: writes Drape's default avatar (game/avatar_generator.hpp).
#include <cstdio>
#include <memory>
#include <string>

#include "game/avatar_generator.hpp"
#include "game/commands.hpp"

namespace drape {

void add_make_avatar_command(CLI::App& app) {
    auto out = std::make_shared<std::string>("assets/avatar.glb");
    CLI::App* command = app.add_subcommand("make-avatar", "Generate the default avatar (mesh, skeleton, walk and idle clips) as binary glTF");
    command->add_option("--out", *out, "Where to write the .glb file")->capture_default_str();
    command->callback([out] {
        const AvatarModel model = make_default_avatar();
        if (auto written = write_avatar(model, *out); !written) {
            std::fprintf(stderr, "drape make-avatar: %s\n", written.error().message.c_str());
            command_exit_code() = 1;
            return;
        }
        std::printf("drape make-avatar: wrote %s (%zu vertices, %zu triangles, %zu bones",
                    out->c_str(), std::size_t(model.positions.cols()),
                    model.triangle_count(), model.bones.size());
        for (const AvatarClip& clip : model.clips) std::printf(", %s %.2f s", clip.name.c_str(), clip.duration_s());
        std::puts(")");
    });
}

}  // namespace drape
