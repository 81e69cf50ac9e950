// Composing poses and skinning (method §1.1, §1.2). See skinning.hpp.
#include "drape/engine/assets/skinning.hpp"

#include <cassert>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace drape {
namespace {

using Matrix34 = Eigen::Matrix<Real, 3, 4>;

// Blends the 3x4 skinning matrices of vertex j's influences.
inline Matrix34 blend(const MeshAsset& mesh, std::span<const Matrix34> matrices, Eigen::Index j) noexcept {
    const auto idx = mesh.bone_indices.col(j);
    const auto w = mesh.bone_weights.col(j);
    Matrix34 m = w[0] * matrices[static_cast<std::size_t>(idx[0])];
    for (int k = 1; k < 4; ++k)
        if (w[k] != 0) m += w[k] * matrices[static_cast<std::size_t>(idx[k])];
    return m;
}

std::vector<Matrix34> to_space_matrices(std::span<const Affine3> skinning, const Affine3& to_space) {
    std::vector<Matrix34> out(skinning.size());
    for (std::size_t b = 0; b < skinning.size(); ++b) out[b] = (to_space * skinning[b]).matrix().topRows<3>();
    return out;
}

// Vertices per parallel block; small meshes are skinned on the calling thread.
constexpr Eigen::Index block_vertices = 2048;
constexpr Eigen::Index parallel_threshold = 8192;

template <class F>
void for_blocks(Eigen::Index n, F&& f) {
    if (n < parallel_threshold) {
        f(Eigen::Index(0), n);
        return;
    }
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, block_vertices),
                      [&](const tbb::blocked_range<Eigen::Index>& r) { f(r.begin(), r.end()); });
}

}  // namespace

void compose_pose(const SkeletonAsset& skeleton, std::span<const Affine3> local, std::vector<Affine3>& global) {
    const std::size_t n = skeleton.size();
    assert(local.size() == n && "compose_pose: one local transform per bone");
    global.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const int p = skeleton.parents[i];
        assert(p < static_cast<int>(i) && "compose_pose: parents must precede children");
        global[i] = p < 0 ? local[i] : global[static_cast<std::size_t>(p)] * local[i];
    }
}

void skinning_matrices(const SkeletonAsset& skeleton, std::span<const Affine3> global,
                       std::vector<Affine3>& skinning) {
    const std::size_t n = skeleton.size();
    skinning.resize(n);
    for (std::size_t i = 0; i < n; ++i) skinning[i] = global[i] * skeleton.inverse_bind[i];
}

void skin_mesh(const MeshAsset& mesh, std::span<const Affine3> skinning, const Affine3& to_space,
               Matrix3X& positions, Matrix3X& normals) {
    const Eigen::Index n = mesh.bind_positions.cols();
    positions.resize(3, n);
    normals.resize(3, n);
    const std::vector<Matrix34> m = to_space_matrices(skinning, to_space);
    const bool has_normals = mesh.bind_normals.cols() == n;
    for_blocks(n, [&](Eigen::Index begin, Eigen::Index end) {
        for (Eigen::Index j = begin; j < end; ++j) {
            const Matrix34 b = blend(mesh, m, j);
            positions.col(j) = b.leftCols<3>() * mesh.bind_positions.col(j) + b.col(3);
            if (has_normals) {
                // The blended linear part is a rotation times a uniform scale for rigid rigs;
                // renormalising is enough (no inverse transpose).
                const Vec3 nrm = b.leftCols<3>() * mesh.bind_normals.col(j);
                const Real len = nrm.norm();
                normals.col(j) = len > Real(1e-12) ? Vec3(nrm / len) : Vec3::UnitY();
            } else {
                normals.col(j) = Vec3::UnitY();
            }
        }
    });
}

void skin_positions(const MeshAsset& mesh, std::span<const Affine3> skinning, const Affine3& to_space,
                    Matrix3X& positions) {
    const Eigen::Index n = mesh.bind_positions.cols();
    positions.resize(3, n);
    const std::vector<Matrix34> m = to_space_matrices(skinning, to_space);
    for_blocks(n, [&](Eigen::Index begin, Eigen::Index end) {
        for (Eigen::Index j = begin; j < end; ++j) {
            const Matrix34 b = blend(mesh, m, j);
            positions.col(j) = b.leftCols<3>() * mesh.bind_positions.col(j) + b.col(3);
        }
    });
}

Affine3 rigid_part(const Affine3& transform) noexcept {
    Affine3 out = Affine3::Identity();
    out.translation() = transform.translation();
    // A rotation times a positive scale along its own axes (orthogonal columns: every bone
    // of a rig without shear, a uniformly scaled Transform) has that rotation as its polar
    // factor, and the normalised columns are it: no SVD. Anything else (shear, a mirror)
    // takes the polar decomposition.
    const Mat3 m = transform.linear();
    const Vec3 lengths = m.colwise().norm();
    if (lengths.minCoeff() > Real(1e-12)) {
        const Mat3 q = m * lengths.cwiseInverse().asDiagonal();
        const Mat3 gram = q.transpose() * q;
        if ((gram - Mat3::Identity()).cwiseAbs().maxCoeff() < Real(1e-5) && q.determinant() > 0) {
            out.linear() = q;
            return out;
        }
    }
    out.linear() = transform.rotation();  // polar decomposition (SVD)
    return out;
}

}  // namespace drape
