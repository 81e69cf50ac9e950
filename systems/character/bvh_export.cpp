// A clip as a BVH file; conventions in bvh_export.hpp.
#include "drape/systems/character/bvh_export.hpp"

#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <vector>

#include "drape/engine/assets/skinning.hpp"
#include "drape/systems/character/pose.hpp"

namespace drape {

Result<void> write_bvh_motion(const std::filesystem::path& path, const AnimationClip& clip, const SkeletonAsset& skeleton,
                              double frames_per_s, const std::function<std::string(std::string_view)>& rename) {
    const std::string at = path.string();
    std::error_code ec;
    if (std::filesystem::exists(path, ec)) return fail(at + ": exists (not overwritten)");
    if (!(frames_per_s > 0) || !std::isfinite(frames_per_s)) return fail(at + ": frames per second must be > 0");
    const std::size_t n = skeleton.size();
    int root = -1;
    for (std::size_t b = 0; b < n; ++b)
        if (skeleton.parents[b] < 0) {
            if (root >= 0) return fail(at + ": the skeleton has more than one root ('" + skeleton.bone_names[std::size_t(root)] + "', '" +
                                       skeleton.bone_names[b] + "')");
            root = static_cast<int>(b);
        }
    if (root < 0) return fail(at + ": the skeleton has no bones");
    std::vector<Affine3> rest_global, local, global;
    compose_pose(skeleton, skeleton.rest_local, rest_global);
    std::vector<std::vector<std::size_t>> children(n);
    for (std::size_t b = 0; b < n; ++b)
        if (skeleton.parents[b] >= 0) children[std::size_t(skeleton.parents[b])].push_back(b);
    const auto name_of = [&](std::size_t b) { return rename ? rename(skeleton.bone_names[b]) : skeleton.bone_names[b]; };

    // Bones the clip moves (the hips of a rig whose root stands still): position channels too.
    std::vector<bool> moves(n, false);
    for (const BoneChannel& ch : clip.channels)
        if (ch.bone >= 0 && static_cast<std::size_t>(ch.bone) < n && !ch.positions.empty()) moves[std::size_t(ch.bone)] = true;
    std::ostringstream out;
    out.precision(7);
    std::vector<std::size_t> order;  // joints in the file's order
    const auto write_joint = [&](auto&& self, std::size_t b, int depth) -> void {
        const std::string pad(static_cast<std::size_t>(2 * depth), ' ');
        const int parent = skeleton.parents[b];
        const Vec3 offset = Vec3(rest_global[b].translation()) -
                            (parent < 0 ? Vec3::Zero() : Vec3(rest_global[std::size_t(parent)].translation()));
        out << pad << (parent < 0 ? "ROOT " : "JOINT ") << name_of(b) << "\n" << pad << "{\n";
        out << pad << "  OFFSET " << offset.x() << ' ' << offset.y() << ' ' << offset.z() << "\n";
        out << pad << "  CHANNELS " << (parent < 0 || moves[b] ? "6 Xposition Yposition Zposition " : "3 ") << "Zrotation Xrotation Yrotation\n";
        order.push_back(b);
        for (std::size_t c : children[b]) self(self, c, depth + 1);
        if (children[b].empty()) out << pad << "  End Site\n" << pad << "  {\n" << pad << "    OFFSET 0 0.05 0\n" << pad << "  }\n";
        out << pad << "}\n";
    };
    out << "HIERARCHY\n";
    write_joint(write_joint, std::size_t(root), 0);
    const int frames = static_cast<int>(std::floor(clip.duration_s * frames_per_s + 1e-9)) + 1;
    out << "MOTION\nFrames: " << frames << "\nFrame Time: " << 1.0 / frames_per_s << "\n";
    std::vector<Quat> rest(n), turn(n);
    for (std::size_t b = 0; b < n; ++b) rest[b] = Quat(rigid_part(rest_global[b]).linear()).normalized();
    for (int f = 0; f < frames; ++f) {
        sample_clip(clip, skeleton, std::min(clip.duration_s, f / frames_per_s), false, local);
        compose_pose(skeleton, local, global);
        for (std::size_t b = 0; b < n; ++b) turn[b] = (Quat(rigid_part(global[b]).linear()) * rest[b].conjugate()).normalized();
        for (std::size_t k = 0; k < order.size(); ++k) {
            const std::size_t b = order[k];
            const int parent = skeleton.parents[b];
            if (parent < 0 || moves[b]) {
                // The root: its place; a moving joint: its offset from its parent in the
                // parent's turned frame.
                const Vec3 place = parent < 0 ? Vec3(global[b].translation())
                                              : Vec3(turn[std::size_t(parent)].conjugate() *
                                                     Vec3(global[b].translation() - global[std::size_t(parent)].translation()));
                out << place.x() << ' ' << place.y() << ' ' << place.z() << ' ';
            }
            const Quat q = parent < 0 ? turn[b] : (turn[std::size_t(parent)].conjugate() * turn[b]).normalized();
            const Vec3 zxy = q.toRotationMatrix().eulerAngles(2, 0, 1) * static_cast<Real>(180 / std::numbers::pi);
            out << zxy[0] << ' ' << zxy[1] << ' ' << zxy[2] << (k + 1 < order.size() ? ' ' : '\n');
        }
    }
    std::ofstream file(path);
    file << out.str();
    if (!file) return fail(at + ": cannot write");
    return {};
}

}  // namespace drape
