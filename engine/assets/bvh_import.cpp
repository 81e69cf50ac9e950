// BVH motion onto an imported character (character_import.hpp: import_bvh_motion).
//
// A BVH joint drives the bone of the same name; the hierarchy must agree (same parent
// names below the BVH root). Rotations of non-root joints are used as they are (the BVH
// must be authored for this skeleton's rest orientation); the root's rotation and
// translation are given in the BVH's world, which is taken as the character's model space,
// with translation rescaled by the ratio of the character's bone lengths to the BVH's.
#include <cmath>
#include <string>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "drape/engine/assets/character_import.hpp"
#include "drape/engine/assets/skinning.hpp"

namespace drape {

Result<std::shared_ptr<const AnimationClip>> import_bvh_motion(const std::filesystem::path& path,
                                                               const SkeletonAsset& skeleton) {
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

    std::vector<Affine3> rest_global;
    compose_pose(skeleton, skeleton.rest_local, rest_global);

    // Match joints to bones; check the hierarchy and gather bone lengths for the unit ratio.
    std::string missing;
    int missing_count = 0;
    double bvh_length = 0, character_length = 0;
    const aiNode* bvh_root = nullptr;
    for (unsigned c = 0; c < anim->mNumChannels; ++c) {
        const aiNodeAnim* ch = anim->mChannels[c];
        const int bone = skeleton.find(ch->mNodeName.C_Str());
        if (bone < 0) {
            if (missing_count++ < 8) missing += (missing.empty() ? "'" : ", '") + std::string(ch->mNodeName.C_Str()) + "'";
            continue;
        }
        const aiNode* node = scene->mRootNode->FindNode(ch->mNodeName);
        if (node == nullptr) continue;
        const aiNode* parent = node->mParent;
        const bool is_root = parent == nullptr || skeleton.find(parent->mName.C_Str()) < 0;
        if (is_root) {
            if (bvh_root != nullptr) return fail(at + ": more than one root joint ('" + std::string(bvh_root->mName.C_Str()) + "', '" + ch->mNodeName.C_Str() + "')");
            bvh_root = node;
            continue;
        }
        const int parent_bone = skeleton.parents[static_cast<std::size_t>(bone)];
        if (parent_bone < 0 || skeleton.bone_names[static_cast<std::size_t>(parent_bone)] != parent->mName.C_Str())
            return fail(at + ": joint '" + std::string(ch->mNodeName.C_Str()) + "' hangs from '" + parent->mName.C_Str() +
                        "' but the character's bone hangs from '" +
                        (parent_bone < 0 ? std::string("nothing") : skeleton.bone_names[static_cast<std::size_t>(parent_bone)]) + "'");
        const aiMatrix4x4& m = node->mTransformation;
        bvh_length += std::sqrt(double(m.a4) * m.a4 + double(m.b4) * m.b4 + double(m.c4) * m.c4);
        character_length += (rest_global[static_cast<std::size_t>(parent_bone)].linear() *
                             skeleton.rest_translation[static_cast<std::size_t>(bone)]).norm();
    }
    if (missing_count > 0)
        return fail(at + ": " + std::to_string(missing_count) + " joint(s) not in the character: " + missing +
                    (missing_count > 8 ? ", ..." : ""));
    if (bvh_root == nullptr) return fail(at + ": no root joint");
    const double unit = bvh_length > 0 && character_length > 0 ? character_length / bvh_length : 1.0;

    auto clip = std::make_shared<AnimationClip>();
    clip->name = path.stem().string();
    const double ticks = anim->mTicksPerSecond > 0 ? anim->mTicksPerSecond : 25;
    double last = 0;
    for (unsigned c = 0; c < anim->mNumChannels; ++c) {
        const aiNodeAnim* ch = anim->mChannels[c];
        BoneChannel out;
        out.bone = skeleton.find(ch->mNodeName.C_Str());
        const bool root = std::string_view(ch->mNodeName.C_Str()) == bvh_root->mName.C_Str();
        const int parent = skeleton.parents[static_cast<std::size_t>(out.bone)];
        const Affine3 parent_global = parent < 0 ? Affine3::Identity() : rest_global[static_cast<std::size_t>(parent)];
        const Affine3 to_parent = parent_global.inverse();
        const Quat parent_rotation(rigid_part(parent_global).linear());
        const std::string cat = at + ": joint '" + std::string(ch->mNodeName.C_Str()) + "'";
        for (unsigned k = 0; k < ch->mNumRotationKeys; ++k) {
            const auto& key = ch->mRotationKeys[k];
            Quat q(key.mValue.w, key.mValue.x, key.mValue.y, key.mValue.z);
            if (!std::isfinite(key.mTime) || !q.coeffs().allFinite() || q.norm() < 1e-6f)
                return fail(cat + ": non-finite rotation key " + std::to_string(k));
            const float t = static_cast<float>(key.mTime / ticks);
            if (!out.rotation_times_s.empty() && t <= out.rotation_times_s.back()) continue;
            out.rotation_times_s.push_back(t);
            out.rotations.push_back(root ? (parent_rotation.conjugate() * q.normalized()).normalized() : q.normalized());
            last = std::max(last, double(t));
        }
        if (root)
            for (unsigned k = 0; k < ch->mNumPositionKeys; ++k) {
                const auto& key = ch->mPositionKeys[k];
                const Vec3 p(key.mValue.x, key.mValue.y, key.mValue.z);
                if (!std::isfinite(key.mTime) || !p.allFinite()) return fail(cat + ": non-finite position key " + std::to_string(k));
                const float t = static_cast<float>(key.mTime / ticks);
                if (!out.position_times_s.empty() && t <= out.position_times_s.back()) continue;
                out.position_times_s.push_back(t);
                out.positions.push_back(to_parent * Vec3(p * static_cast<Real>(unit)));
                last = std::max(last, double(t));
            }
        clip->channels.push_back(std::move(out));
    }
    clip->duration_s = std::max(std::isfinite(anim->mDuration) ? anim->mDuration / ticks : 0.0, last);
    if (!(clip->duration_s > 0)) return fail(at + ": motion has no duration (one frame?)");
    compute_clip_travel(*clip, skeleton);
    return std::shared_ptr<const AnimationClip>(std::move(clip));
}

}  // namespace drape
