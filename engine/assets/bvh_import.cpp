// BVH motion onto an imported character, retargeted (character_import.hpp: import_bvh_motion;
// docs/characters.md, "Motion from a BVH file").
//
// Conventions
// - A BVH's rest pose is its joints' offsets with every rotation zero; its world is taken as
//   the character's model space (Y up), in the BVH's units.
// - Per frame the joints' world rotations G_s come from the BVH's own hierarchy (joints that
//   drive nothing still turn their children). A driven bone b of joint j turns in the world
//   as j turns from the motion's rest: G_b = G_s(j) C_b G_b,rest, with C_b the rest
//   correction: the rotation that takes b's rest direction onto j's (toward the next driven
//   bone and joint of the same part: the thigh toward the shin, the spine toward the neck);
//   for the hips the frame of their up (toward the spine) and left-right (thigh to thigh)
//   axes. A bone no joint drives keeps its rest rotation relative to its parent. The clip
//   holds each driven bone's rotation relative to its parent's.
// - The root joint's position, times the ratio of the character's leg length (hips above the
//   lowest bone at rest) to the motion's (hips above its lowest joint at rest), is the hips'
//   place in model space.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <string>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "drape/engine/assets/character_import.hpp"
#include "drape/engine/assets/skinning.hpp"

namespace drape {

namespace {

bool contains(std::string_view s, std::string_view part) { return s.find(part) != std::string_view::npos; }

// The side a name gives ('l', 'r', or 0) and the name without it, lower case, without
// separators.
std::pair<char, std::string> split_side(std::string_view raw) {
    // Namespaces and rig prefixes: "mixamorig:LeftArm", "Armature|Hips", "Bip01 L Thigh".
    if (const auto colon = raw.find_last_of(":|"); colon != std::string_view::npos) raw = raw.substr(colon + 1);
    std::string name(raw);
    char side = 0;
    const auto lower_of = [](std::string s) {
        std::string out;
        for (char c : s)
            if (std::isalnum(static_cast<unsigned char>(c))) out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        return out;
    };
    const auto sep = [](char c) { return c == '.' || c == '_' || c == ' ' || c == '-'; };
    const std::size_t n = name.size();
    // A trailing side: ".L", "_r", " L", or a capital after a lower-case letter ("UpperLegL").
    if (n >= 2 && (name[n - 1] == 'L' || name[n - 1] == 'R' || name[n - 1] == 'l' || name[n - 1] == 'r') &&
        (sep(name[n - 2]) || (std::isupper(static_cast<unsigned char>(name[n - 1])) && std::islower(static_cast<unsigned char>(name[n - 2]))))) {
        side = static_cast<char>(std::tolower(static_cast<unsigned char>(name[n - 1])));
        name.resize(n - 1);
    } else if (n >= 2 && (name[0] == 'L' || name[0] == 'R' || name[0] == 'l' || name[0] == 'r') &&
               (sep(name[1]) || (std::isupper(static_cast<unsigned char>(name[0])) && std::isupper(static_cast<unsigned char>(name[1]))))) {
        // A leading side: "L_Thigh", "l_arm", "LHipJoint" (a capital before a capital).
        side = static_cast<char>(std::tolower(static_cast<unsigned char>(name[0])));
        name = name.substr(1);
    }
    std::string lower = lower_of(name);
    if (side == 0) {
        for (const auto& [word, s] : {std::pair{"left", 'l'}, std::pair{"right", 'r'}}) {
            if (lower.rfind(word, 0) == 0) {
                side = s;
                lower = lower.substr(std::string_view(word).size());
                break;
            }
            if (lower.size() > std::string_view(word).size() && lower.ends_with(word)) {
                side = s;
                lower.resize(lower.size() - std::string_view(word).size());
                break;
            }
        }
    }
    return {side, lower};
}

}  // namespace

std::string humanoid_part(std::string_view bone_name) {
    const auto [side, n] = split_side(bone_name);
    for (const char* finger : {"thumb", "index", "middle", "ring", "pinky", "finger", "twist", "roll", "end", "ik", "pole", "target"})
        if (contains(n, finger)) return {};
    std::string part;
    if (side == 0) {
        if (n == "hips" || n == "hip" || n == "pelvis") return "hips";
        if (contains(n, "neck")) return "neck";
        if (n.rfind("head", 0) == 0 && !contains(n, "top")) return "head";
        if (contains(n, "spine") || contains(n, "chest") || contains(n, "torso") || contains(n, "abdomen") || contains(n, "back") ||
            contains(n, "belly"))
            return "spine";
        return {};
    }
    if (contains(n, "upleg") || contains(n, "upperleg") || contains(n, "thigh") || contains(n, "femur"))
        part = "upper_leg";
    else if (contains(n, "lowerleg") || contains(n, "shin") || contains(n, "calf") || contains(n, "knee") || n == "leg" || n == "lowleg")
        part = "lower_leg";
    else if (contains(n, "toe") || contains(n, "ball"))
        part = "toe";
    else if (contains(n, "foot") || contains(n, "ankle"))
        part = "foot";
    else if (contains(n, "shoulder") || contains(n, "clavicle") || contains(n, "collar"))
        part = "shoulder";
    else if (contains(n, "forearm") || contains(n, "lowerarm") || contains(n, "elbow") || n == "lowarm")
        part = "lower_arm";
    else if (contains(n, "upperarm") || n == "arm" || n == "uparm" || contains(n, "humerus"))
        part = "upper_arm";
    else if (contains(n, "hand") || contains(n, "wrist") || contains(n, "fist") || contains(n, "palm"))
        part = "hand";
    else
        return {};
    return part + "." + side;
}

namespace {

// The rotation taking unit vector `from` onto unit vector `to` (the shortest; identity for
// a degenerate pair).
Quat rotation_between(const Vec3& from, const Vec3& to) {
    if (!(from.norm() > 1e-6f) || !(to.norm() > 1e-6f)) return Quat::Identity();
    return Quat::FromTwoVectors(from.normalized(), to.normalized());
}

// The frame of two axes: `up`, and `side` made orthogonal to it (columns side, up, side x up).
Mat3 frame_of(const Vec3& up, const Vec3& side) {
    const Vec3 u = up.normalized();
    const Vec3 s = (side - side.dot(u) * u).normalized();
    Mat3 f;
    f.col(0) = s;
    f.col(1) = u;
    f.col(2) = s.cross(u);
    return f;
}

struct Joint {
    const aiNode* node = nullptr;
    int parent = -1;                 ///< Index into the joints, -1 for the root.
    const aiNodeAnim* channel = nullptr;
    Vec3 offset = Vec3::Zero();      ///< Rest offset from the parent (BVH units).
    Vec3 rest_world = Vec3::Zero();  ///< Rest position (BVH units).
    std::string part;
    int bone = -1;                   ///< The bone it drives, -1 for none.
};

}  // namespace

Result<std::shared_ptr<const AnimationClip>> import_bvh_motion(const std::filesystem::path& path, const SkeletonAsset& skeleton,
                                                               const MotionRetarget& retarget, std::vector<std::string>* notes) {
    const std::string at = path.string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return fail(at + ": no such file");
    Assimp::Importer importer;
    importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
    const aiScene* scene = importer.ReadFile(path.string(), 0);
    if (scene == nullptr) {
        std::string why = importer.GetErrorString();
        for (char& c : why) if (c == '\n' || c == '\r') c = ' ';
        return fail(at + ": not a readable motion (" + why + ")");
    }
    if (scene->mNumAnimations == 0 || scene->mAnimations[0]->mNumChannels == 0) return fail(at + ": no animation");
    const aiAnimation* anim = scene->mAnimations[0];

    // The motion's joints, parents first: the nodes that have a channel, under the root.
    std::map<std::string, const aiNodeAnim*> channels;
    for (unsigned c = 0; c < anim->mNumChannels; ++c) channels[anim->mChannels[c]->mNodeName.C_Str()] = anim->mChannels[c];
    std::vector<Joint> joints;
    const auto walk = [&](auto&& self, const aiNode* node, int parent) -> void {
        int me = parent;
        if (const auto it = channels.find(node->mName.C_Str()); it != channels.end()) {
            Joint j;
            j.node = node;
            j.parent = parent;
            j.channel = it->second;
            const aiMatrix4x4& m = node->mTransformation;
            j.offset = Vec3(m.a4, m.b4, m.c4);
            j.rest_world = (parent >= 0 ? joints[static_cast<std::size_t>(parent)].rest_world : Vec3::Zero()) + j.offset;
            me = static_cast<int>(joints.size());
            joints.push_back(j);
        }
        for (unsigned k = 0; k < node->mNumChildren; ++k) self(self, node->mChildren[k], me);
    };
    walk(walk, scene->mRootNode, -1);
    if (joints.empty()) return fail(at + ": no joint has motion");
    if (std::count_if(joints.begin(), joints.end(), [](const Joint& j) { return j.parent < 0; }) != 1)
        return fail(at + ": more than one root joint");

    // Match: the same name, the scene's map, the same humanoid part.
    std::vector<std::string> bone_part(skeleton.size());
    for (std::size_t b = 0; b < skeleton.size(); ++b) bone_part[b] = humanoid_part(skeleton.bone_names[b]);
    std::vector<int> driven_by(skeleton.size(), -1);
    // A skeleton without two legs (a tail, a prop, a creature) takes a motion made for it:
    // every joint names one of its bones. (The pelvis is found where the legs meet.)
    const auto has_part = [&](std::string_view part) { return std::find(bone_part.begin(), bone_part.end(), part) != bone_part.end(); };
    const bool humanoid = has_part("upper_leg.l") && has_part("upper_leg.r") && has_part("lower_leg.l") && has_part("lower_leg.r");
    if (!humanoid) {
        std::string missing;
        int missing_count = 0;
        for (const Joint& j : joints)
            if (skeleton.find(j.node->mName.C_Str()) < 0 && missing_count++ < 8)
                missing += (missing.empty() ? "'" : ", '") + std::string(j.node->mName.C_Str()) + "'";
        if (missing_count > 0)
            return fail(at + ": " + std::to_string(missing_count) + " joint(s) not in the character: " + missing +
                        (missing_count > 8 ? ", ..." : "") + " (it has no two legs to match a humanoid motion by)");
    }
    for (std::size_t j = 0; j < joints.size(); ++j) {
        Joint& joint = joints[j];
        const std::string name = joint.node->mName.C_Str();
        joint.part = humanoid_part(name);
        int bone = -1;
        for (const auto& [from, to] : retarget.bones)
            if (from == name) {
                bone = skeleton.find(to);
                if (bone < 0) return fail(at + ": motion_bones maps joint '" + name + "' to '" + to + "', which the character does not have");
            }
        if (bone < 0) bone = skeleton.find(name);
        if (bone < 0 && !joint.part.empty() && joint.part != "spine")
            for (std::size_t b = 0; b < skeleton.size(); ++b)
                if (bone_part[b] == joint.part && driven_by[b] < 0) {
                    bone = static_cast<int>(b);
                    break;
                }
        if (bone >= 0 && driven_by[static_cast<std::size_t>(bone)] < 0) {
            joint.bone = bone;
            driven_by[static_cast<std::size_t>(bone)] = static_cast<int>(j);
        }
    }
    const auto find_part = [](const auto& parts, std::string_view part) -> int {
        for (std::size_t k = 0; k < parts.size(); ++k)
            if (parts[k] == part) return static_cast<int>(k);
        return -1;
    };
    std::vector<std::string> joint_parts;
    for (const Joint& j : joints) joint_parts.push_back(j.part);
    // The pelvis on both sides: where the two legs meet (the lowest common ancestor of the
    // thighs; a rig may hang its spine from a "Hips" bone beside the legs), else by name.
    const auto meet = [](const std::vector<int>& parent, int a, int b) {
        std::vector<bool> above_a(parent.size(), false);
        for (int k = a; k >= 0; k = parent[static_cast<std::size_t>(k)]) above_a[static_cast<std::size_t>(k)] = true;
        for (int k = parent[static_cast<std::size_t>(b)]; k >= 0; k = parent[static_cast<std::size_t>(k)])
            if (above_a[static_cast<std::size_t>(k)] && k != a) return k;
        return -1;
    };
    std::vector<int> joint_parent;
    for (const Joint& j : joints) joint_parent.push_back(j.parent);
    int hips_joint = -1, hips_bone = -1;
    if (const int l = find_part(joint_parts, "upper_leg.l"), r = find_part(joint_parts, "upper_leg.r"); l >= 0 && r >= 0)
        hips_joint = meet(joint_parent, l, r);
    if (hips_joint < 0) hips_joint = find_part(joint_parts, "hips") >= 0 ? find_part(joint_parts, "hips") : 0;
    if (const int l = find_part(bone_part, "upper_leg.l"), r = find_part(bone_part, "upper_leg.r"); humanoid && l >= 0 && r >= 0)
        hips_bone = meet(skeleton.parents, l, r);
    if (hips_bone < 0) hips_bone = joints[static_cast<std::size_t>(hips_joint)].bone;
    if (hips_bone < 0) hips_bone = find_part(bone_part, "hips");
    if (hips_bone >= 0) {
        // The pelvis is driven by the motion's pelvis, and by nothing else.
        Joint& pelvis = joints[static_cast<std::size_t>(hips_joint)];
        if (pelvis.bone >= 0 && pelvis.bone != hips_bone) driven_by[static_cast<std::size_t>(pelvis.bone)] = -1;
        if (const int other = driven_by[static_cast<std::size_t>(hips_bone)]; other >= 0 && other != hips_joint)
            joints[static_cast<std::size_t>(other)].bone = -1;
        pelvis.bone = hips_bone;
        driven_by[static_cast<std::size_t>(hips_bone)] = hips_joint;
    }
    // The spine: the chains from the pelvis to the neck, matched by their share of the chain.
    const int neck_joint = find_part(joint_parts, "neck"), neck_bone = find_part(bone_part, "neck");
    if (hips_bone >= 0 && neck_joint >= 0 && neck_bone >= 0) {
        std::vector<int> source, target;  // from the neck's parent down to the hips' child
        for (int j = joints[static_cast<std::size_t>(neck_joint)].parent; j >= 0 && j != hips_joint; j = joints[static_cast<std::size_t>(j)].parent)
            source.push_back(j);
        for (int b = skeleton.parents[static_cast<std::size_t>(neck_bone)]; b >= 0 && b != hips_bone; b = skeleton.parents[static_cast<std::size_t>(b)])
            target.push_back(b);
        std::reverse(source.begin(), source.end());
        std::reverse(target.begin(), target.end());
        // Target bone k takes the joint at the same share of the chain (several bones may
        // share a joint: each then turns in the world as it turns).
        for (std::size_t k = 0; k < target.size() && !source.empty(); ++k) {
            const auto b = static_cast<std::size_t>(target[k]);
            if (driven_by[b] >= 0) continue;
            const std::size_t s = std::min(source.size() - 1, (2 * k + 1) * source.size() / (2 * target.size()));
            driven_by[b] = source[s];
            if (joints[static_cast<std::size_t>(source[s])].bone < 0) joints[static_cast<std::size_t>(source[s])].bone = target[k];
        }
    }
    // What must be there.
    std::string missing;
    if (humanoid) {
        for (const char* part : {"hips", "upper_leg.l", "upper_leg.r", "lower_leg.l", "lower_leg.r"}) {
            const int b = find_part(bone_part, part);
            const bool matched = std::string_view(part) == "hips" ? hips_bone >= 0 && driven_by[static_cast<std::size_t>(hips_bone)] >= 0
                                                                  : b >= 0 && driven_by[static_cast<std::size_t>(b)] >= 0;
            if (!matched) missing += std::string(missing.empty() ? "" : ", ") + part;
        }
    }
    if (!missing.empty()) {
        std::string names;
        for (const Joint& j : joints) names += std::string(names.empty() ? "" : ", ") + j.node->mName.C_Str();
        return fail(at + ": no joint drives the character's " + missing + " (joints: " + names +
                    "; name them in the scene's motion_bones)");
    }
    if (notes != nullptr) {
        std::string idle, undriven;
        int idle_count = 0;
        for (const Joint& j : joints)
            if (j.bone < 0 && !j.part.empty() && idle_count++ < 12) idle += std::string(idle.empty() ? "" : ", ") + j.node->mName.C_Str();
        for (std::size_t b = 0; b < skeleton.size(); ++b)
            if (driven_by[b] < 0 && !bone_part[b].empty())
                undriven += std::string(undriven.empty() ? "" : ", ") + skeleton.bone_names[b];
        if (!idle.empty() || !undriven.empty())
            notes->push_back(at + ": motion: " + (idle.empty() ? "" : "joints driving no bone: " + idle) +
                             (idle.empty() || undriven.empty() ? "" : "; ") +
                             (undriven.empty() ? "" : "bones no joint drives (they keep their rest pose): " + undriven));
    }

    // Rest of both: the character's world rest, and the corrections.
    std::vector<Affine3> rest_global;
    compose_pose(skeleton, skeleton.rest_local, rest_global);
    std::vector<Quat> rest_rotation(skeleton.size());
    for (std::size_t b = 0; b < skeleton.size(); ++b) rest_rotation[b] = Quat(rigid_part(rest_global[b]).linear()).normalized();
    const auto bone_at = [&](int b) { return Vec3(rest_global[static_cast<std::size_t>(b)].translation()); };
    const auto joint_at = [&](int j) { return joints[static_cast<std::size_t>(j)].rest_world; };
    // The next driven bone of a part, and its joint: toward which the rest directions point.
    const std::map<std::string, std::string> next_part = {
        {"upper_leg", "lower_leg"}, {"lower_leg", "foot"}, {"foot", "toe"},
        {"shoulder", "upper_arm"}, {"upper_arm", "lower_arm"}, {"lower_arm", "hand"}};
    std::vector<Quat> correction(joints.size(), Quat::Identity());
    for (std::size_t j = 0; j < joints.size(); ++j) {
        const Joint& joint = joints[j];
        if (joint.bone < 0) continue;
        int toward_joint = -1;
        if (const auto dot = joint.part.find('.'); dot != std::string::npos) {
            if (const auto it = next_part.find(joint.part.substr(0, dot)); it != next_part.end())
                toward_joint = find_part(joint_parts, it->second + joint.part.substr(dot));
        } else if (joint.part == "spine" || static_cast<int>(j) == hips_joint) {
            // The pelvis and the spine: toward the neck, the trunk as one (a rig's short
            // spine bones may point anywhere: RobotExpressive's first one hangs below its
            // pelvis). The neck: toward the head.
            toward_joint = neck_joint;
        } else if (joint.part == "neck") {
            toward_joint = find_part(joint_parts, "head");
        }
        if (toward_joint < 0 || joints[static_cast<std::size_t>(toward_joint)].bone < 0) {
            // An end (a hand, a foot without toes, the head): its nearest driven ancestor's.
            for (int up = joint.parent; up >= 0; up = joints[static_cast<std::size_t>(up)].parent)
                if (joints[static_cast<std::size_t>(up)].bone >= 0) {
                    correction[j] = correction[static_cast<std::size_t>(up)];
                    break;
                }
            continue;
        }
        const Vec3 motion_dir = joint_at(toward_joint) - joint_at(static_cast<int>(j));
        const Vec3 bone_dir = bone_at(joints[static_cast<std::size_t>(toward_joint)].bone) - bone_at(joint.bone);
        if (static_cast<int>(j) == hips_joint) {
            const int lj = find_part(joint_parts, "upper_leg.l"), rj = find_part(joint_parts, "upper_leg.r");
            const int lb = find_part(bone_part, "upper_leg.l"), rb = find_part(bone_part, "upper_leg.r");
            if (lj >= 0 && rj >= 0 && lb >= 0 && rb >= 0) {
                const Mat3 motion_frame = frame_of(motion_dir, joint_at(lj) - joint_at(rj));
                const Mat3 bone_frame = frame_of(bone_dir, bone_at(lb) - bone_at(rb));
                if (motion_frame.allFinite() && bone_frame.allFinite()) correction[j] = Quat(Mat3(motion_frame * bone_frame.transpose())).normalized();
                continue;
            }
        }
        correction[j] = rotation_between(bone_dir, motion_dir);
    }
    // The legs' lengths: the hips above the lowest driven bone, and above the lowest joint
    // that drives one, at rest.
    double motion_low = joint_at(hips_joint).y(), bone_low = bone_at(hips_bone).y();
    for (std::size_t j = 0; j < joints.size(); ++j)
        if (joints[j].bone >= 0) motion_low = std::min(motion_low, double(joints[j].rest_world.y()));
    for (std::size_t b = 0; b < skeleton.size(); ++b)
        if (driven_by[b] >= 0) bone_low = std::min(bone_low, double(bone_at(static_cast<int>(b)).y()));
    const double motion_legs = joint_at(hips_joint).y() - motion_low, bone_legs = bone_at(hips_bone).y() - bone_low;
    double scale = motion_legs > 1e-9 && bone_legs > 1e-9 ? bone_legs / motion_legs : 0.0;
    if (scale == 0) {
        // No legs below the hips (a column, a tail): the ratio of the driven bones' lengths.
        double motion_length = 0, bone_length = 0;
        for (const Joint& j : joints)
            if (j.bone >= 0 && j.parent >= 0) {
                motion_length += j.offset.norm();
                bone_length += (bone_at(j.bone) - bone_at(std::max(0, skeleton.parents[static_cast<std::size_t>(j.bone)]))).norm();
            }
        scale = motion_length > 1e-9 && bone_length > 1e-9 ? bone_length / motion_length : 1.0;
    }

    // Frames: the root's rotation keys (a BVH keys every channel on every frame).
    const aiNodeAnim* root_channel = joints.front().channel;
    const unsigned frames = root_channel->mNumRotationKeys;
    if (frames < 2) return fail(at + ": motion has no duration (one frame?)");
    for (const Joint& j : joints)
        if (j.channel->mNumRotationKeys != frames)
            return fail(at + ": joint '" + std::string(j.node->mName.C_Str()) + "' has " + std::to_string(j.channel->mNumRotationKeys) +
                        " rotation keys, the root " + std::to_string(frames));
    const double ticks = anim->mTicksPerSecond > 0 ? anim->mTicksPerSecond : 25;

    // A limb part that does not hang below its chain's previous part (a rig's IK foot under
    // its root) is placed each frame where that part puts it, as at rest.
    const std::map<std::string, std::string> previous_part = {
        {"lower_leg", "upper_leg"}, {"foot", "lower_leg"}, {"toe", "foot"},
        {"upper_arm", "shoulder"}, {"lower_arm", "upper_arm"}, {"hand", "lower_arm"}};
    std::vector<int> placed_from(skeleton.size(), -1);
    bool any_placed = false;
    for (std::size_t b = 0; b < skeleton.size(); ++b) {
        const auto dot = bone_part[b].find('.');
        if (driven_by[b] < 0 || dot == std::string::npos) continue;
        const auto it = previous_part.find(bone_part[b].substr(0, dot));
        if (it == previous_part.end()) continue;
        const int before = find_part(bone_part, it->second + bone_part[b].substr(dot));
        if (before < 0 || driven_by[static_cast<std::size_t>(before)] < 0) continue;
        bool below = false;
        for (int up = skeleton.parents[b]; up >= 0 && !below; up = skeleton.parents[static_cast<std::size_t>(up)]) below = up == before;
        if (!below) {
            placed_from[b] = before;
            any_placed = true;
        }
    }

    auto clip = std::make_shared<AnimationClip>();
    clip->name = path.stem().string();
    std::vector<int> channel_of(skeleton.size(), -1);
    for (std::size_t b = 0; b < skeleton.size(); ++b)
        if (driven_by[b] >= 0) {
            channel_of[b] = static_cast<int>(clip->channels.size());
            clip->channels.emplace_back().bone = static_cast<int>(b);
        }
    std::vector<Affine3> pose(skeleton.size());
    std::vector<Quat> joint_world(joints.size()), bone_world(skeleton.size());
    std::vector<Vec3> joint_place(joints.size(), Vec3::Zero());
    double last = 0;
    for (unsigned f = 0; f < frames; ++f) {
        const double time = root_channel->mRotationKeys[f].mTime;
        if (!std::isfinite(time)) return fail(at + ": non-finite key time at frame " + std::to_string(f));
        const float t = static_cast<float>(time / ticks);
        if (f > 0 && !(t > clip->channels.front().rotation_times_s.back())) continue;
        for (std::size_t j = 0; j < joints.size(); ++j) {
            const auto& key = joints[j].channel->mRotationKeys[f].mValue;
            Quat q(key.w, key.x, key.y, key.z);
            if (!q.coeffs().allFinite() || q.norm() < 1e-6f)
                return fail(at + ": joint '" + std::string(joints[j].node->mName.C_Str()) + "': non-finite rotation at frame " + std::to_string(f));
            q.normalize();
            const int parent = joints[j].parent;
            if (parent < 0) {
                const auto& key_p = joints[j].channel->mPositionKeys[std::min(f, joints[j].channel->mNumPositionKeys - 1)].mValue;
                joint_place[j] = joints[j].channel->mNumPositionKeys > 0 ? Vec3(key_p.x, key_p.y, key_p.z) : joints[j].offset;
                joint_world[j] = q;
            } else {
                const auto up = static_cast<std::size_t>(parent);
                // A joint with position channels moves from its parent by them, else by its offset.
                const aiNodeAnim* ch = joints[j].channel;
                Vec3 offset = joints[j].offset;
                if (ch->mNumPositionKeys == frames) {
                    const auto& key_p = ch->mPositionKeys[f].mValue;
                    offset = Vec3(key_p.x, key_p.y, key_p.z);
                }
                joint_place[j] = joint_place[up] + joint_world[up] * offset;
                joint_world[j] = (joint_world[up] * q).normalized();
            }
        }
        for (std::size_t b = 0; b < skeleton.size(); ++b) {
            const int parent = skeleton.parents[b];
            const Quat parent_world = parent < 0 ? Quat::Identity() : bone_world[static_cast<std::size_t>(parent)];
            const Quat parent_rest = parent < 0 ? Quat::Identity() : rest_rotation[static_cast<std::size_t>(parent)];
            if (driven_by[b] < 0) {
                bone_world[b] = parent < 0 ? rest_rotation[b] : (parent_world * parent_rest.conjugate() * rest_rotation[b]).normalized();
                continue;
            }
            const auto j = static_cast<std::size_t>(driven_by[b]);
            bone_world[b] = (joint_world[j] * correction[j] * rest_rotation[b]).normalized();
            // Relative to the parent's world rotation.
            const Quat local = parent_world.conjugate() * bone_world[b];
            BoneChannel& ch = clip->channels[static_cast<std::size_t>(channel_of[b])];
            ch.rotation_times_s.push_back(t);
            ch.rotations.push_back(local.normalized());
        }
        // The hips' place: the hips joint's, through the motion's hierarchy from its root.
        const Vec3 p = joint_place[static_cast<std::size_t>(hips_joint)];
        if (!p.allFinite()) return fail(at + ": non-finite root position at frame " + std::to_string(f));
        const Vec3 model = p * static_cast<Real>(scale) + Vec3(0, static_cast<Real>(bone_low - motion_low * scale), 0);
        const int hips_parent = skeleton.parents[static_cast<std::size_t>(hips_bone)];
        const Vec3 hips_local = (hips_parent < 0 ? Affine3::Identity() : rest_global[static_cast<std::size_t>(hips_parent)]).inverse() * model;
        {
            BoneChannel& ch = clip->channels[static_cast<std::size_t>(channel_of[static_cast<std::size_t>(hips_bone)])];
            ch.position_times_s.push_back(t);
            ch.positions.push_back(hips_local);
        }
        if (any_placed) {
            // This frame's pose, then each placed part where its previous part's end is.
            for (std::size_t b = 0; b < skeleton.size(); ++b) {
                const int parent = skeleton.parents[b];
                const Quat rotation = parent < 0 ? bone_world[b] : (bone_world[static_cast<std::size_t>(parent)].conjugate() * bone_world[b]).normalized();
                Affine3 local = Affine3::Identity();
                local.translate(static_cast<int>(b) == hips_bone ? hips_local : skeleton.rest_translation[b]);
                local.rotate(rotation);
                local.scale(skeleton.rest_scale[b]);
                pose[b] = parent < 0 ? local : pose[static_cast<std::size_t>(parent)] * local;
            }
            for (std::size_t b = 0; b < skeleton.size(); ++b) {
                if (placed_from[b] < 0) continue;
                const auto before = static_cast<std::size_t>(placed_from[b]);
                const Vec3 place = pose[before] * (rest_global[before].inverse() * Vec3(rest_global[b].translation()));
                const int parent = skeleton.parents[b];
                BoneChannel& ch = clip->channels[static_cast<std::size_t>(channel_of[b])];
                ch.position_times_s.push_back(t);
                ch.positions.push_back(parent < 0 ? place : Vec3(pose[static_cast<std::size_t>(parent)].inverse() * place));
            }
        }
        last = std::max(last, double(t));
    }
    clip->duration_s = std::max(std::isfinite(anim->mDuration) ? anim->mDuration / ticks : 0.0, last);
    if (!(clip->duration_s > 0)) return fail(at + ": motion has no duration (one frame?)");
    compute_clip_travel(*clip, skeleton);
    blend_loop_seam(*clip);
    return std::shared_ptr<const AnimationClip>(std::move(clip));
}

}  // namespace drape
