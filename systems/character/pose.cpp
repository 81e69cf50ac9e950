// Sampling clips into local poses (method §1.1). See pose.hpp.
#include "drape/systems/character/pose.hpp"

#include <algorithm>
#include <cmath>

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
                 std::vector<Affine3>& local, bool loop) {
    rest_pose(skeleton, local);
    if (!std::isfinite(time_s)) time_s = 0;  // never let a bad clock reach the pose
    const int bones = static_cast<int>(skeleton.size());
    // The seam's share at this time: 0 before the blend, 1 at the clip's end (smoothstep).
    Real seam = 0;
    if (loop && clip.seam_blend_s > 0 && time_s > clip.duration_s - clip.seam_blend_s) {
        const Real u = static_cast<Real>(std::min(1.0, (time_s - (clip.duration_s - clip.seam_blend_s)) / clip.seam_blend_s));
        seam = u * u * (3 - 2 * u);
    }
    for (const BoneChannel& c : clip.channels) {
        if (c.bone < 0 || c.bone >= bones) continue;
        const auto b = static_cast<std::size_t>(c.bone);
        Vec3 t = c.positions.empty() ? skeleton.rest_translation[b]
                                     : lerp_keys(c.position_times_s, c.positions, time_s);
        Quat r = c.rotations.empty() ? skeleton.rest_rotation[b]
                                     : slerp_keys(c.rotation_times_s, c.rotations, time_s);
        if (seam > 0) {
            if (c.rotations.size() >= 2) {
                const Quat gap = (c.rotations.front() * c.rotations.back().conjugate()).normalized();
                r = (Quat::Identity().slerp(seam, gap) * r).normalized();
            }
            if (c.positions.size() >= 2) {
                Vec3 gap = c.positions.front() - c.positions.back();
                if (c.bone == clip.motion_bone) gap += clip.travel_local;  // the cycle's travel stays
                t += seam * gap;
            }
        }
        const Vec3 s = c.scales.empty() ? skeleton.rest_scale[b] : lerp_keys(c.scale_times_s, c.scales, time_s);
        if (in_place && c.bone == clip.motion_bone && clip.duration_s > 0)
            t -= clip.travel_local * static_cast<Real>(time_s / clip.duration_s);
        local[b] = compose_trs(t, r, s);
    }
}

}  // namespace drape
