// `drape export-motion CHARACTER --out FILE.bvh [--clip NAME] [--fps N]`: writes one of a
// character's clips as a BVH motion (systems/character/bvh_export.hpp), which `drape play
// --motion` or a scene's "motion" field then plays on any humanoid (docs/characters.md).
// Never overwrites a file.
#include <cstdio>
#include <memory>
#include <string>

#include "drape/engine/assets/character_import.hpp"
#include "drape/game/commands.hpp"
#include "drape/systems/character/bvh_export.hpp"

namespace drape {

void add_export_motion_command(CLI::App& app) {
    struct Options {
        std::string character, out, clip;
        double fps = 30;
    };
    auto o = std::make_shared<Options>();
    CLI::App* command = app.add_subcommand("export-motion", "Write a character's clip as a BVH motion (played on any humanoid with play --motion)");
    command->add_option("character", o->character, "Character file (.glb/.gltf/.fbx/...)")->required()->check(not_empty());
    command->add_option("--out", o->out, "The .bvh file to write (never overwritten)")->required()->check(not_empty());
    command->add_option("--clip", o->clip, "Clip name or index (default: the clip play would choose)")->check(not_empty());
    command->add_option("--fps", o->fps, "Frames per second")->check(CLI::Range(1.0, 1000.0))->capture_default_str();
    command->callback([o] {
        auto error = [](const std::string& message) { command_error("export-motion", message); };
        auto character = import_character(o->character);
        if (!character) return error(character.error().message);
        std::size_t index = 0;
        if (!o->clip.empty()) {
            auto found = find_clip(**character, o->clip);
            if (!found) return error("--clip: " + found.error().message);
            index = *found;
        } else if (const auto choice = choose_default_clip(**character)) {
            index = choice->index;
        } else {
            return error(o->character + ": no clips to export");
        }
        const AnimationClip& clip = *(*character)->clips.at(index);
        if (auto ok = write_bvh_motion(o->out, clip, *(*character)->skeleton, o->fps); !ok) return error("--out: " + ok.error().message);
        std::printf("drape export-motion: wrote %s (%s, %.2f s, %zu joints)\n", o->out.c_str(), clip.name.c_str(), clip.duration_s,
                    (*character)->skeleton->size());
    });
}

}  // namespace drape
