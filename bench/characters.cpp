#include "bench/characters.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <system_error>

#include "bench/world.hpp"
#include "drape/game/asset_paths.hpp"

namespace drape::bench {

namespace fs = std::filesystem;

std::vector<CharacterFile> character_files() {
    std::vector<CharacterFile> list;
    list.push_back({"default avatar", default_avatar_path(), true});
    const fs::path shared = shared_characters_dir();
    std::error_code ec;
    std::vector<fs::path> files;
    for (const auto& folder : fs::directory_iterator(shared, ec)) {
        if (!folder.is_directory()) continue;
        for (const auto& entry : fs::directory_iterator(folder.path(), ec)) {
            std::string ext = entry.path().extension().string();
            std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
            if (ext == ".fbx" || ext == ".glb" || ext == ".gltf") files.push_back(entry.path());
        }
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) list.push_back({f.stem().string(), f, false});
    return list;
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char ch) { return std::tolower(ch); });
    return s;
}

bool matches_filter(const std::string& name, const std::string& filter) {
    const std::string n = lower(name);
    std::size_t from = 0;
    while (from <= filter.size()) {
        const std::size_t comma = std::min(filter.find(',', from), filter.size());
        const std::string word = lower(filter.substr(from, comma - from));
        if (!word.empty() && n.find(word) == std::string::npos) return false;
        from = comma + 1;
    }
    return true;
}

std::string clip_kind(const std::string& full_name) {
    const std::string n = lower(full_name.substr(full_name.rfind('|') == std::string::npos ? 0 : full_name.rfind('|') + 1));
    const auto has = [&](const char* word) { return n.find(word) != std::string::npos; };
    if (has("run") && has("jump")) return "running jump";
    if (has("walk") && !has("jump")) return "walk";
    if (has("run") || has("jog")) return "run";
    if (has("jump")) return "jump";
    if (has("idle")) return "idle";
    if (has("punch") || has("attack") || has("slash") || has("kick")) return "attack";
    if (has("sit")) return "sitting";
    if (has("death") || has("dead") || has("die")) return "death";
    return "";
}

std::vector<std::pair<std::string, const AnimationClip*>> chosen_clips(const CharacterAsset& asset) {
    static const std::array<const char*, 8> kinds = {"walk", "run", "jump", "running jump", "idle", "attack", "sitting", "death"};
    std::vector<std::pair<std::string, const AnimationClip*>> chosen;
    for (const char* kind : kinds) {
        const AnimationClip* first = nullptr;
        const AnimationClip* plain = nullptr;
        for (const auto& clip : asset.clips) {
            if (!clip || clip_kind(clip->name) != kind) continue;
            if (!first) first = clip.get();
            const std::string n = lower(clip->name);
            const bool variant = n.find("back") != std::string::npos || n.find("left") != std::string::npos ||
                                 n.find("right") != std::string::npos || n.find("gun") != std::string::npos;
            if (!variant) {
                plain = clip.get();
                break;
            }
        }
        const AnimationClip* pick = plain ? plain : first;
        if (pick) chosen.emplace_back(kind, pick);
    }
    return chosen;
}

}  // namespace drape::bench
