// Drape's default avatar: a smooth humanoid with a skeleton, skin weights and a walk cycle,
// generated here rather than copied from anywhere (docs/avatar.md).
//
// The body is the zero set of a signed distance field, a smooth union of tapered capsules
// and ellipsoids hung on the bones, meshed with surface nets; skin weights come from how
// close each vertex is to each bone's shapes. The walk is a procedural in-place gait cycle.
// Everything is deterministic: the same options give the same bytes on every run.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/math.hpp"

struct aiScene;

namespace drape {

/// What to generate. The defaults make `assets/avatar.glb`.
struct AvatarOptions {
    double height_m = 1.75;        ///< Standing height, sole to crown.
    double grid_spacing_m = 0.017; ///< Surface-nets cell size before scaling by height / 1.75.
    int keys_per_second = 30;      ///< Key frame rate of the clips.
};

/// One joint of the avatar's skeleton. Bind pose: every bone frame is parallel to model
/// space (no rotation), so a bone's bind transform is a translation to its joint.
struct AvatarBone {
    std::string name;
    int parent = -1;          ///< Index of the parent bone, -1 for the root; parent < own index.
    Eigen::Vector3d joint_m;  ///< Joint position in model space at bind, metres.
};

/// A clip as dense key frames, one key per bone per frame: frame k is at k / keys_per_second
/// seconds, and the last frame repeats the first so the clip loops without a seam.
struct AvatarClip {
    std::string name;
    int keys_per_second = 30;
    std::vector<std::vector<Eigen::Vector3d>> translations;  ///< [frame][bone]: bone -> parent translation.
    std::vector<std::vector<Eigen::Quaterniond>> rotations;  ///< [frame][bone]: bone -> parent rotation.

    [[nodiscard]] int frame_count() const noexcept { return static_cast<int>(rotations.size()); }
    [[nodiscard]] double duration_s() const noexcept {
        return rotations.empty() ? 0.0 : double(rotations.size() - 1) / keys_per_second;
    }
};

/// The generated avatar: skeleton, skinned triangle mesh in bind pose, clips.
struct AvatarModel {
    std::vector<AvatarBone> bones;
    Matrix3X positions;                                           ///< Bind pose, model space, metres.
    Matrix3X normals;                                             ///< Unit, outward.
    std::vector<std::uint32_t> indices;                           ///< Triangles, counter-clockwise seen from outside.
    Eigen::Matrix<std::int32_t, 4, Eigen::Dynamic> bone_indices;  ///< Up to 4 influences (unused: 0 with weight 0).
    Matrix4X bone_weights;                                        ///< Each column sums to 1.
    std::vector<AvatarClip> clips;                                ///< "Walk" first, then "Idle".

    [[nodiscard]] std::size_t triangle_count() const noexcept { return indices.size() / 3; }
    /// Index of a bone by name, -1 when absent.
    [[nodiscard]] int find_bone(std::string_view name) const noexcept;
};

/// Builds the avatar. Deterministic: equal options give identical models. Options out of
/// range are the caller's to check (default_avatar_glb and write_default_avatar do).
[[nodiscard]] AvatarModel make_default_avatar(const AvatarOptions& options = {});

/// The model as an assimp scene (one skinned mesh, the bone hierarchy, one animation per
/// clip), ready for Assimp::Exporter.
[[nodiscard]] std::unique_ptr<aiScene> to_assimp_scene(const AvatarModel& model);

/// A model as binary glTF 2.0 bytes, written by assimp's `glb2` exporter.
[[nodiscard]] Result<std::vector<std::uint8_t>> avatar_glb(const AvatarModel& model);

/// The default avatar as binary glTF 2.0 bytes (the contents of `assets/avatar.glb`).
[[nodiscard]] Result<std::vector<std::uint8_t>> default_avatar_glb(const AvatarOptions& options = {});

/// Writes a model to `path` as binary glTF 2.0.
[[nodiscard]] Result<void> write_avatar(const AvatarModel& model, const std::filesystem::path& path);

/// Writes the avatar to `path` as binary glTF 2.0 (the committed `assets/avatar.glb`).
[[nodiscard]] Result<void> write_default_avatar(const std::filesystem::path& path,
                                                const AvatarOptions& options = {});

}  // namespace drape
