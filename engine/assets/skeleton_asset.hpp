// A character's bones as imported: hierarchy, rest (node) pose and bind pose (method §1.1).
// Shared, immutable data; the per-instance pose is components/skeleton.hpp.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "drape/engine/core/math.hpp"

namespace drape {

/// Immutable skeleton data shared by every instance of a character.
struct SkeletonAsset {
    std::vector<std::string> bone_names;
    std::vector<int> parents;            ///< -1 for a root; parents[i] < i (sorted parent first).
    std::vector<Affine3> rest_local;     ///< Node pose: bone -> parent, metres, Y up.
    std::vector<Affine3> inverse_bind;   ///< Model space at bind -> bone space (skinning).
    // rest_local split into translation, rotation and scale: what a bone keeps for the
    // parts a clip does not animate.
    std::vector<Vec3> rest_translation;
    std::vector<Quat> rest_rotation;
    std::vector<Vec3> rest_scale;

    [[nodiscard]] std::size_t size() const noexcept { return parents.size(); }
    /// Index of a bone by name, -1 when absent.
    [[nodiscard]] int find(std::string_view name) const noexcept {
        for (std::size_t i = 0; i < bone_names.size(); ++i)
            if (bone_names[i] == name) return static_cast<int>(i);
        return -1;
    }
};

}  // namespace drape
