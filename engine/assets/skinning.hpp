// Pose composition and linear blend skinning on imported data (method §1.1, §1.2): plain
// transform math. The importer needs it to measure the rest pose (its height decides the
// file's units) and to place BVH motion; the animation and skinning systems build each
// frame from it (systems/character/pose.hpp).
#pragma once

#include <span>
#include <vector>

#include "drape/engine/assets/mesh_asset.hpp"
#include "drape/engine/assets/skeleton_asset.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// Composes local transforms down the hierarchy into model space. Parents precede children.
void compose_pose(const SkeletonAsset& skeleton, std::span<const Affine3> local, std::vector<Affine3>& global);

/// global * inverse_bind per bone: bind model space -> current model space.
void skinning_matrices(const SkeletonAsset& skeleton, std::span<const Affine3> global,
                       std::vector<Affine3>& skinning);

/// Linear blend skinning of every vertex: positions and normals in the space `to_space`
/// maps model space to (the character's Transform for world space). Runs in parallel
/// over blocks of vertices for big meshes. Outputs are resized.
void skin_mesh(const MeshAsset& mesh, std::span<const Affine3> skinning, const Affine3& to_space,
               Matrix3X& positions, Matrix3X& normals);

/// The same for positions only (fitting, coverage, cloth pinning).
void skin_positions(const MeshAsset& mesh, std::span<const Affine3> skinning, const Affine3& to_space,
                    Matrix3X& positions);

/// The rigid part of a transform (rotation and translation; scale and shear removed).
[[nodiscard]] Affine3 rigid_part(const Affine3& transform) noexcept;

}  // namespace drape
