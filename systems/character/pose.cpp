// Sampling, composing and skinning (method §1.1, §1.2). See pose.hpp.
#include "systems/character/pose.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace drape {
namespace {

// Index i of the key interval [times[i], times[i+1]] holding t, and the blend factor.
struct KeySpan {
    std::size_t i = 0;
    Real alpha = 0;
    bool single = true;
};

KeySpan find_span(const std::vector<float>& times, double t) noexcept {
    // Compare in the keys' own precision: a double just below the last key can round up
    // to it in float, and the search must then take the end branch.
    const std::size_t n = times.size();
    const auto tf = static_cast<float>(t);
    if (n <= 1 || !(tf > times.front())) return {0, 0, true};
    if (tf >= times.back()) return {n - 1, 0, true};
    const auto upper = std::upper_bound(times.begin(), times.end(), tf);
    const std::size_t i = static_cast<std::size_t>(upper - times.begin()) - 1;
    const double span = double(times[i + 1]) - double(times[i]);
    const Real alpha = span > 0 ? static_cast<Real>((t - times[i]) / span) : Real(0);
    return {i, std::clamp(alpha, Real(0), Real(1)), false};
}

template <class V>
V lerp_keys(const std::vector<float>& times, const std::vector<V>& values, double t) {
    const KeySpan s = find_span(times, t);
    if (s.single) return values[s.i];
    return values[s.i] + s.alpha * (values[s.i + 1] - values[s.i]);
}

Quat slerp_keys(const std::vector<float>& times, const std::vector<Quat>& values, double t) {
    const KeySpan s = find_span(times, t);
    if (s.single) return values[s.i];
    return values[s.i].slerp(s.alpha, values[s.i + 1]).normalized();  // Eigen takes the shorter arc
}

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

ClipTime wrap_clip_time(double time_s, double duration_s, bool loop) noexcept {
    if (!std::isfinite(time_s) || duration_s <= 0) return {0, 0};
    if (!loop) return {std::clamp(time_s, 0.0, duration_s), 0};
    const double cycles = std::floor(time_s / duration_s);
    double t = time_s - cycles * duration_s;
    if (t < 0) t = 0;
    if (t > duration_s) t = duration_s;
    return {t, static_cast<int>(cycles)};
}

Affine3 compose_trs(const Vec3& translation, const Quat& rotation, const Vec3& scale) noexcept {
    Affine3 m = Affine3::Identity();
    m.linear() = rotation.toRotationMatrix() * scale.asDiagonal();
    m.translation() = translation;
    return m;
}

void rest_pose(const SkeletonAsset& skeleton, std::vector<Affine3>& local) {
    local.assign(skeleton.rest_local.begin(), skeleton.rest_local.end());
}

void sample_clip(const AnimationClip& clip, const SkeletonAsset& skeleton, double time_s, bool in_place,
                 std::vector<Affine3>& local) {
    rest_pose(skeleton, local);
    if (!std::isfinite(time_s)) time_s = 0;  // never let a bad clock reach the pose
    const int bones = static_cast<int>(skeleton.size());
    for (const BoneChannel& c : clip.channels) {
        if (c.bone < 0 || c.bone >= bones) continue;
        const auto b = static_cast<std::size_t>(c.bone);
        Vec3 t = c.positions.empty() ? skeleton.rest_translation[b]
                                     : lerp_keys(c.position_times_s, c.positions, time_s);
        const Quat r = c.rotations.empty() ? skeleton.rest_rotation[b]
                                           : slerp_keys(c.rotation_times_s, c.rotations, time_s);
        const Vec3 s = c.scales.empty() ? skeleton.rest_scale[b] : lerp_keys(c.scale_times_s, c.scales, time_s);
        if (in_place && c.bone == clip.motion_bone && clip.duration_s > 0)
            t -= clip.travel_local * static_cast<Real>(time_s / clip.duration_s);
        local[b] = compose_trs(t, r, s);
    }
}

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
    out.linear() = transform.rotation();  // polar decomposition (SVD)
    out.translation() = transform.translation();
    return out;
}

}  // namespace drape
