// Character import through assimp. See character_import.hpp for the conventions.
//
// Steps: read the scene; choose the skeleton's nodes (every node a skin names, every
// animated node, and their ancestors up to the scene root, in depth-first order so parents
// precede children); build one merged mesh (skinned vertices keep their file weights,
// limited to 4 and normalised; rigid meshes get weight 1 on the bone they hang from);
// convert clips to seconds; correct axes, then units; measure height. Fitting ellipsoids
// to the result is the character systems' work (systems/character/character_body.hpp).
#include "drape/engine/assets/character_import.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cmath>
#include <fstream>
#include <numeric>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include <Eigen/SVD>
#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "drape/engine/assets/skinning.hpp"

namespace drape {

const char* scale_source_name(ScaleSource source) noexcept {
    switch (source) {
        case ScaleSource::option: return "scale option";
        case ScaleSource::height: return "height option";
        case ScaleSource::file_units: return "file units";
        case ScaleSource::fallback: return "fallback height";
    }
    return "?";
}

namespace {

std::string where(const std::filesystem::path& path) { return path.string(); }

// assimp's messages can span lines; Drape's errors are one line.
std::string one_line(std::string text) {
    std::replace(text.begin(), text.end(), '\n', ' ');
    std::replace(text.begin(), text.end(), '\r', ' ');
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
}

Affine3 to_affine(const aiMatrix4x4& m) {
    Mat4 out;
    out << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
    Affine3 a;
    a.matrix() = out;
    return a;
}

bool finite(const Affine3& a) { return a.matrix().allFinite(); }

// An inverse bind matrix skinning can use: finite and invertible. Judged by the ratio of
// its smallest to largest singular value, so the file's units do not matter; a bone
// scaled to zero at bind (or flattened onto a plane) has a ratio of about 0.
bool usable_bind(const Affine3& a) {
    if (!finite(a)) return false;
    const Vec3 s = Eigen::JacobiSVD<Mat3>(a.linear()).singularValues();
    return s(0) > 0 && s(2) > Real(1e-6) * s(0);
}

aiMatrix4x4 node_global(const aiNode* node) {
    aiMatrix4x4 m = node->mTransformation;
    for (const aiNode* p = node->mParent; p != nullptr; p = p->mParent) m = p->mTransformation * m;
    return m;
}

// Decomposes an affine into TRS (shear is lost; rigs do not use it).
void decompose(const Affine3& a, Vec3& t, Quat& r, Vec3& s) {
    Mat3 rotation, scaling;
    a.computeRotationScaling(&rotation, &scaling);
    t = a.translation();
    r = Quat(rotation).normalized();
    s = scaling.diagonal();
}

template <class T>
std::optional<double> metadata_number(const aiScene* scene, const char* key) {
    if (scene->mMetaData == nullptr) return std::nullopt;
    T value{};
    if (scene->mMetaData->Get(key, value)) return static_cast<double>(value);
    return std::nullopt;
}

std::optional<double> metadata_any(const aiScene* scene, const char* key) {
    if (auto d = metadata_number<double>(scene, key)) return d;
    if (auto f = metadata_number<float>(scene, key)) return f;
    if (auto i = metadata_number<int32_t>(scene, key)) return i;
    return std::nullopt;
}

bool source_format_contains(const aiScene* scene, std::string_view what) {
    aiString format;
    if (scene->mMetaData == nullptr || !scene->mMetaData->Get("SourceAsset_Format", format)) return false;
    return std::string_view(format.C_Str()).find(what) != std::string_view::npos;
}

// FBX axis metadata of a scene -> rotation into Drape's axes.
Mat3 fbx_axes(const aiScene* scene) {
    const auto up = metadata_any(scene, "UpAxis"), up_sign = metadata_any(scene, "UpAxisSign");
    const auto front = metadata_any(scene, "FrontAxis"), front_sign = metadata_any(scene, "FrontAxisSign");
    const auto coord = metadata_any(scene, "CoordAxis"), coord_sign = metadata_any(scene, "CoordAxisSign");
    if (!up || !front || !coord) return Mat3::Identity();
    return axes_to_drape(int(*up), up_sign && *up_sign < 0 ? -1 : 1, int(*front), front_sign && *front_sign < 0 ? -1 : 1,
                         int(*coord), coord_sign && *coord_sign < 0 ? -1 : 1);
}

const char* axis_name(double axis, double sign) {
    static const char* names[] = {"-X", "-Y", "-Z", "X", "Y", "Z"};
    const int a = static_cast<int>(axis);
    return a >= 0 && a <= 2 ? names[a + (sign < 0 ? 0 : 3)] : "?";
}

// What a file states of its units (metres per file unit) and up axis, and the line saying so.
struct FileUnits {
    std::optional<double> metres_per_unit;  ///< None: the file states no unit.
    std::string stated;
};

FileUnits file_units(const aiScene* scene, const std::filesystem::path& path) {
    FileUnits out;
    char text[160];
    std::string extension = path.extension().string();
    for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (extension == ".glb" || extension == ".gltf") {
        out.metres_per_unit = 1;
        out.stated = "glTF: metres, Y up (the format's own)";
    } else if (extension == ".dae") {
        out.metres_per_unit = 1;  // assimp applies <unit> and <up_axis> itself (metres and Y up when absent)
        out.stated = "COLLADA: its <unit> and <up_axis>, applied on reading";
    } else if (source_format_contains(scene, "FBX")) {
        const auto unit_cm = metadata_any(scene, "UnitScaleFactor");
        const auto up = metadata_any(scene, "UpAxis"), up_sign = metadata_any(scene, "UpAxisSign");
        const std::string up_text = up ? std::string(", UpAxis ") + axis_name(*up, up_sign.value_or(1)) : std::string(", no UpAxis (Y taken)");
        if (unit_cm && std::isfinite(*unit_cm) && *unit_cm > 0) {
            out.metres_per_unit = *unit_cm * 0.01;
            std::snprintf(text, sizeof text, "FBX: UnitScaleFactor %g (1 unit = %g cm)", *unit_cm, *unit_cm);
            out.stated = text + up_text;
        } else {
            out.stated = "FBX: no UnitScaleFactor" + up_text;
        }
    } else {
        out.stated = "the file states no unit";
    }
    return out;
}

struct Builder {
    Builder(const std::filesystem::path& p, const aiScene* s) : path(p), scene(s) {}
    const std::filesystem::path& path;
    const aiScene* scene = nullptr;
    SkeletonAsset skeleton;
    std::vector<const aiNode*> bone_nodes;
    std::unordered_map<const aiNode*, int> bone_of_node;
    std::vector<Affine3> rest_global;
    std::vector<bool> has_bind;  // inverse_bind came from a skin (else: the node pose)
    std::vector<std::string> warnings;

    [[nodiscard]] std::string at() const { return where(path); }

    // Nearest skeleton bone at or above a node.
    [[nodiscard]] int bone_above(const aiNode* node) const {
        for (const aiNode* n = node; n != nullptr; n = n->mParent)
            if (auto it = bone_of_node.find(n); it != bone_of_node.end()) return it->second;
        return 0;
    }
};

Result<void> build_skeleton(Builder& b) {
    const aiScene* scene = b.scene;
    std::unordered_set<const aiNode*> marked;
    auto mark_with_ancestors = [&](const aiNode* n) {
        for (; n != nullptr && marked.insert(n).second; n = n->mParent) {}
    };
    bool skinned = false;
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* mesh = scene->mMeshes[m];
        for (unsigned i = 0; i < mesh->mNumBones; ++i) {
            const aiNode* node = scene->mRootNode->FindNode(mesh->mBones[i]->mName);
            if (node == nullptr)
                return fail(b.at() + ": mesh '" + mesh->mName.C_Str() + "' is skinned to bone '" +
                            mesh->mBones[i]->mName.C_Str() + "' that is not in the node tree");
            mark_with_ancestors(node);
            skinned = true;
        }
    }
    std::unordered_set<const aiNode*> animated;
    for (unsigned a = 0; a < scene->mNumAnimations; ++a) {
        const aiAnimation* anim = scene->mAnimations[a];
        for (unsigned c = 0; c < anim->mNumChannels; ++c)
            if (const aiNode* node = scene->mRootNode->FindNode(anim->mChannels[c]->mNodeName)) {
                mark_with_ancestors(node);
                animated.insert(node);
            }
    }
    if (!skinned) {
        // Rigid characters are allowed when some mesh hangs from an animated node.
        bool rigid_rig = false;
        std::vector<const aiNode*> stack{scene->mRootNode};
        while (!stack.empty() && !rigid_rig) {
            const aiNode* n = stack.back();
            stack.pop_back();
            if (n->mNumMeshes > 0)
                for (const aiNode* p = n; p != nullptr; p = p->mParent)
                    if (animated.contains(p) && p != scene->mRootNode) { rigid_rig = true; break; }
            for (unsigned i = 0; i < n->mNumChildren; ++i) stack.push_back(n->mChildren[i]);
        }
        if (!rigid_rig) return fail(b.at() + ": no skeleton (no mesh has bones and none hangs from an animated node)");
    }
    marked.insert(scene->mRootNode);

    // Depth-first, parents first.
    struct Item { const aiNode* node; int parent; };
    std::vector<Item> stack{{scene->mRootNode, -1}};
    while (!stack.empty()) {
        const Item item = stack.back();
        stack.pop_back();
        const int index = static_cast<int>(b.bone_nodes.size());
        b.bone_nodes.push_back(item.node);
        b.bone_of_node[item.node] = index;
        b.skeleton.bone_names.emplace_back(item.node->mName.C_Str());
        b.skeleton.parents.push_back(item.parent);
        const Affine3 local = to_affine(item.node->mTransformation);
        if (!finite(local)) return fail(b.at() + ": node '" + item.node->mName.C_Str() + "' has a non-finite transform");
        b.skeleton.rest_local.push_back(local);
        for (unsigned i = item.node->mNumChildren; i-- > 0;)
            if (marked.contains(item.node->mChildren[i])) stack.push_back({item.node->mChildren[i], index});
    }
    compose_pose(b.skeleton, b.skeleton.rest_local, b.rest_global);
    b.skeleton.inverse_bind.resize(b.skeleton.size());
    b.has_bind.assign(b.skeleton.size(), false);
    for (std::size_t i = 0; i < b.skeleton.size(); ++i) b.skeleton.inverse_bind[i] = b.rest_global[i].inverse();
    return {};
}

// The inverse bind of each bone from the first skin that names it: mesh space -> bone,
// turned into model space -> bone through the mesh node's transform. (glTF ignores a
// skinned mesh node's transform when skinning; the product global * inverse_bind * bind
// position is the same either way, but only with the node transform does the bind mesh
// sit in model space, which fitting needs: three.js exports bake that transform into the
// inverse binds.)
void collect_inverse_binds(Builder& b) {
    const aiScene* scene = b.scene;
    std::unordered_map<const aiMesh*, Affine3> mesh_global;
    std::vector<const aiNode*> stack{scene->mRootNode};
    while (!stack.empty()) {
        const aiNode* n = stack.back();
        stack.pop_back();
        for (unsigned i = 0; i < n->mNumMeshes; ++i) {
            const aiMesh* mesh = scene->mMeshes[n->mMeshes[i]];
            if (!mesh_global.contains(mesh)) mesh_global[mesh] = to_affine(node_global(n));
        }
        for (unsigned i = 0; i < n->mNumChildren; ++i) stack.push_back(n->mChildren[i]);
    }
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
        const aiMesh* mesh = scene->mMeshes[m];
        const auto g = mesh_global.find(mesh);
        if (g == mesh_global.end()) continue;
        for (unsigned i = 0; i < mesh->mNumBones; ++i) {
            const aiNode* node = scene->mRootNode->FindNode(mesh->mBones[i]->mName);
            const int bone = b.bone_of_node.at(node);
            if (b.has_bind[static_cast<std::size_t>(bone)]) continue;
            const Affine3 offset = to_affine(mesh->mBones[i]->mOffsetMatrix);
            if (!usable_bind(offset)) continue;  // build_mesh names the bone (an error when it has weights)
            b.skeleton.inverse_bind[static_cast<std::size_t>(bone)] = offset * g->second.inverse();
            b.has_bind[static_cast<std::size_t>(bone)] = true;
        }
    }
}

Vec3 material_color(const aiScene* scene, const aiMesh* mesh) {
    if (mesh->mMaterialIndex >= scene->mNumMaterials) return Vec3(0.8f, 0.7f, 0.6f);
    const aiMaterial* material = scene->mMaterials[mesh->mMaterialIndex];
    aiColor4D c;
    if (material->Get(AI_MATKEY_BASE_COLOR, c) == AI_SUCCESS || material->Get(AI_MATKEY_COLOR_DIFFUSE, c) == AI_SUCCESS)
        return Vec3(c.r, c.g, c.b).cwiseMax(0.f).cwiseMin(1.f);
    return Vec3(0.8f, 0.7f, 0.6f);
}

Result<void> build_mesh(Builder& b, MeshAsset& out, std::vector<MeshInfo>& infos) {
    const aiScene* scene = b.scene;
    struct Placed { const aiMesh* mesh; const aiNode* node; };
    std::vector<Placed> placed;
    std::vector<const aiNode*> stack{scene->mRootNode};
    std::vector<const aiNode*> order;
    while (!stack.empty()) {  // depth-first, children in file order
        const aiNode* n = stack.back();
        stack.pop_back();
        for (unsigned i = 0; i < n->mNumMeshes; ++i) placed.push_back({scene->mMeshes[n->mMeshes[i]], n});
        for (unsigned i = n->mNumChildren; i-- > 0;) stack.push_back(n->mChildren[i]);
    }
    std::size_t vertex_total = 0;
    for (const Placed& p : placed)
        if (p.mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) vertex_total += p.mesh->mNumVertices;
    if (vertex_total == 0) return fail(b.at() + ": no triangle meshes");

    const auto n = static_cast<Eigen::Index>(vertex_total);
    out.bind_positions.resize(3, n);
    out.bind_normals.resize(3, n);
    out.bone_indices.setZero(4, n);
    out.bone_weights.setZero(4, n);
    out.uvs.setZero(2, n);
    Eigen::Index base = 0;
    for (const Placed& p : placed) {
        const aiMesh* mesh = p.mesh;
        if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
        const std::string mesh_name = mesh->mName.length > 0 ? mesh->mName.C_Str() : p.node->mName.C_Str();
        const unsigned nv = mesh->mNumVertices;
        // Influences per vertex: (bone, weight), then the bind position through the dominant bone.
        std::vector<std::vector<std::pair<int, float>>> influences(nv);
        std::vector<Affine3> offsets(mesh->mNumBones);
        std::vector<int> offset_bone(mesh->mNumBones);
        for (unsigned i = 0; i < mesh->mNumBones; ++i) {
            const aiBone* bone = mesh->mBones[i];
            const int index = b.bone_of_node.at(scene->mRootNode->FindNode(bone->mName));
            offsets[i] = to_affine(bone->mOffsetMatrix);
            offset_bone[i] = index;
            if (!usable_bind(offsets[i])) {
                // Skinning maps a vertex through the inverse of this matrix: with weights on the
                // bone its vertices would collapse (zero scale) or go non-finite. Without weights
                // the bone only moves its children (exporters write such end bones).
                const std::string why = std::string(finite(offsets[i]) ? "singular (zero scale)" : "non-finite") +
                                        " inverse bind matrix";
                const auto weighted = std::count_if(bone->mWeights, bone->mWeights + bone->mNumWeights,
                                                    [](const aiVertexWeight& w) { return w.mWeight > 0; });
                if (weighted > 0)
                    return fail(b.at() + ": mesh '" + mesh_name + "': bone '" + bone->mName.C_Str() + "' has a " + why +
                                " but " + std::to_string(weighted) + " vertices are skinned to it");
                b.warnings.push_back(b.at() + ": mesh '" + mesh_name + "': bone '" + bone->mName.C_Str() + "' has a " + why +
                                     " and no skinned vertices, ignored");
            }
            for (unsigned w = 0; w < bone->mNumWeights; ++w) {
                const aiVertexWeight& vw = bone->mWeights[w];
                if (!std::isfinite(vw.mWeight) || vw.mWeight < 0)
                    return fail(b.at() + ": mesh '" + mesh_name + "': " +
                                (std::isfinite(vw.mWeight) ? "negative" : "non-finite") + " weight on bone '" +
                                bone->mName.C_Str() + "' at vertex " + std::to_string(vw.mVertexId));
                if (vw.mVertexId >= nv || vw.mWeight == 0) continue;
                influences[vw.mVertexId].push_back({static_cast<int>(i), vw.mWeight});
            }
        }
        const int rigid_bone = b.bone_above(p.node);
        const Affine3 rigid_to_bind = b.skeleton.inverse_bind[static_cast<std::size_t>(rigid_bone)].inverse() *
                                      b.rest_global[static_cast<std::size_t>(rigid_bone)].inverse() *
                                      to_affine(node_global(p.node));
        bool any_rigid = false;
        for (unsigned v = 0; v < nv; ++v) {
            const Eigen::Index j = base + v;
            const aiVector3D& pv = mesh->mVertices[v];
            const Vec3 position(pv.x, pv.y, pv.z);
            const Vec3 normal = mesh->mNormals ? Vec3(mesh->mNormals[v].x, mesh->mNormals[v].y, mesh->mNormals[v].z)
                                               : Vec3::UnitY();
            if (!position.allFinite())
                return fail(b.at() + ": mesh '" + mesh_name + "': non-finite position at vertex " + std::to_string(v));
            auto& inf = influences[v];
            std::sort(inf.begin(), inf.end(), [](auto& x, auto& y) { return x.second > y.second; });
            if (inf.size() > 4) inf.resize(4);
            float sum = 0;
            for (auto& [i, w] : inf) sum += w;
            if (sum <= 1e-8f && mesh->mNumBones > 0)
                // assimp drops weights it cannot read (NaN in glTF): a skinned vertex left
                // without any is bad data, not a rigid part.
                return fail(b.at() + ": mesh '" + mesh_name + "': vertex " + std::to_string(v) +
                            " has no finite, positive bone weight (non-finite or missing weights)");
            if (sum <= 1e-8f) {
                any_rigid = true;
                out.bone_indices.col(j) << rigid_bone, 0, 0, 0;
                out.bone_weights.col(j) << 1, 0, 0, 0;
                out.bind_positions.col(j) = rigid_to_bind * position;
                out.bind_normals.col(j) = (rigid_to_bind.linear() * normal).normalized();
            } else {
                for (std::size_t k = 0; k < inf.size(); ++k) {
                    out.bone_indices(static_cast<Eigen::Index>(k), j) = offset_bone[static_cast<std::size_t>(inf[k].first)];
                    out.bone_weights(static_cast<Eigen::Index>(k), j) = inf[k].second / sum;
                }
                // Mesh space -> model space at bind, through the dominant bone's bind.
                const int dominant = inf.front().first;
                const Affine3 to_bind =
                    b.skeleton.inverse_bind[static_cast<std::size_t>(offset_bone[static_cast<std::size_t>(dominant)])]
                        .inverse() * offsets[static_cast<std::size_t>(dominant)];
                out.bind_positions.col(j) = to_bind * position;
                out.bind_normals.col(j) = (to_bind.linear() * normal).normalized();
            }
            if (!out.bind_normals.col(j).allFinite()) out.bind_normals.col(j) = Vec3::UnitY();
            if (mesh->HasTextureCoords(0)) out.uvs.col(j) = Eigen::Vector2f(mesh->mTextureCoords[0][v].x, mesh->mTextureCoords[0][v].y);
        }
        Submesh sub;
        sub.name = mesh_name;
        sub.first_index = static_cast<std::uint32_t>(out.indices.size());
        for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
            const aiFace& face = mesh->mFaces[f];
            if (face.mNumIndices != 3) continue;
            for (int k = 0; k < 3; ++k) {
                if (face.mIndices[k] >= nv)
                    return fail(b.at() + ": mesh '" + mesh_name + "': face " + std::to_string(f) + " indexes past its vertices");
                out.indices.push_back(static_cast<std::uint32_t>(base) + face.mIndices[k]);
            }
        }
        sub.index_count = static_cast<std::uint32_t>(out.indices.size()) - sub.first_index;
        sub.color = material_color(scene, mesh);
        out.submeshes.push_back(sub);
        aiString material;
        if (mesh->mMaterialIndex < scene->mNumMaterials) scene->mMaterials[mesh->mMaterialIndex]->Get(AI_MATKEY_NAME, material);
        infos.push_back({mesh_name, static_cast<std::uint32_t>(base), nv, mesh->mNumBones == 0 || any_rigid, material.C_Str(),
                         mesh->HasTextureCoords(0)});
        base += nv;
    }
    return {};
}

Result<std::shared_ptr<AnimationClip>> build_clip(const Builder& b, const aiAnimation* anim, std::size_t index) {
    auto clip = std::make_shared<AnimationClip>();
    clip->name = anim->mName.length > 0 ? anim->mName.C_Str() : "clip " + std::to_string(index);
    const std::string ctx = b.at() + ": clip '" + clip->name + "'";
    double ticks = anim->mTicksPerSecond;
    if (!std::isfinite(ticks) || ticks < 0) return fail(ctx + ": non-finite ticks per second");
    if (ticks == 0) ticks = 25;  // assimp's documented default
    if (!std::isfinite(anim->mDuration)) return fail(ctx + ": non-finite duration");
    double last_key = 0;
    for (unsigned c = 0; c < anim->mNumChannels; ++c) {
        const aiNodeAnim* ch = anim->mChannels[c];
        const aiNode* node = b.scene->mRootNode->FindNode(ch->mNodeName);
        if (node == nullptr) continue;  // animates a node that no longer exists
        BoneChannel out;
        out.bone = b.bone_of_node.at(node);
        const std::string cctx = ctx + ", bone '" + ch->mNodeName.C_Str() + "'";
        auto time_of = [&](double t, const char* kind, unsigned k) -> Result<float> {
            if (!std::isfinite(t)) return fail(cctx + ": non-finite " + kind + " key time " + std::to_string(k));
            last_key = std::max(last_key, t / ticks);
            return static_cast<float>(t / ticks);
        };
        auto push_time = [](std::vector<float>& times, float t) {
            // assimp may repeat or reorder times; keep them ascending.
            if (!times.empty() && t <= times.back()) return false;
            times.push_back(t);
            return true;
        };
        for (unsigned k = 0; k < ch->mNumPositionKeys; ++k) {
            const auto& key = ch->mPositionKeys[k];
            auto t = time_of(key.mTime, "position", k);
            if (!t) return std::unexpected(t.error());
            const Vec3 v(key.mValue.x, key.mValue.y, key.mValue.z);
            if (!v.allFinite()) return fail(cctx + ": non-finite position key " + std::to_string(k));
            if (push_time(out.position_times_s, *t)) out.positions.push_back(v);
        }
        for (unsigned k = 0; k < ch->mNumRotationKeys; ++k) {
            const auto& key = ch->mRotationKeys[k];
            auto t = time_of(key.mTime, "rotation", k);
            if (!t) return std::unexpected(t.error());
            Quat q(key.mValue.w, key.mValue.x, key.mValue.y, key.mValue.z);
            if (!q.coeffs().allFinite()) return fail(cctx + ": non-finite rotation key " + std::to_string(k));
            if (q.norm() < 1e-6f) return fail(cctx + ": zero rotation key " + std::to_string(k));
            if (push_time(out.rotation_times_s, *t)) out.rotations.push_back(q.normalized());
        }
        for (unsigned k = 0; k < ch->mNumScalingKeys; ++k) {
            const auto& key = ch->mScalingKeys[k];
            auto t = time_of(key.mTime, "scale", k);
            if (!t) return std::unexpected(t.error());
            const Vec3 v(key.mValue.x, key.mValue.y, key.mValue.z);
            if (!v.allFinite()) return fail(cctx + ": non-finite scale key " + std::to_string(k));
            if (push_time(out.scale_times_s, *t)) out.scales.push_back(v);
        }
        clip->channels.push_back(std::move(out));
    }
    clip->duration_s = std::max(anim->mDuration / ticks, last_key);
    return clip;
}

// Folds a rotation and uniform scale in front of every root bone: rest pose, its TRS
// parts, the inverse binds (bind model space moves too), bind positions and root keys.
void apply_root_correction(SkeletonAsset& skeleton, MeshAsset& mesh, std::vector<std::shared_ptr<AnimationClip>>& clips,
                           const Mat3& rotation, Real scale) {
    Affine3 c = Affine3::Identity();
    c.linear() = rotation * scale;
    const Affine3 c_inverse = c.inverse();
    const Quat q(rotation);
    for (std::size_t i = 0; i < skeleton.size(); ++i) {
        skeleton.inverse_bind[i] = skeleton.inverse_bind[i] * c_inverse;
        if (skeleton.parents[i] >= 0) continue;
        skeleton.rest_local[i] = c * skeleton.rest_local[i];
        skeleton.rest_translation[i] = scale * (rotation * skeleton.rest_translation[i]);
        skeleton.rest_rotation[i] = (q * skeleton.rest_rotation[i]).normalized();
        skeleton.rest_scale[i] *= scale;
    }
    mesh.bind_positions = (c.linear() * mesh.bind_positions).eval();
    mesh.bind_normals = (rotation * mesh.bind_normals).eval();
    for (auto& clip : clips)
        for (BoneChannel& ch : clip->channels) {
            if (skeleton.parents[static_cast<std::size_t>(ch.bone)] >= 0) continue;
            for (Vec3& p : ch.positions) p = scale * (rotation * p);
            for (Quat& r : ch.rotations) r = (q * r).normalized();
            for (Vec3& s : ch.scales) s *= scale;
        }
}

// Zero-length bones in the rest (node) pose: a bone whose child joints all sit at its own
// joint, or an end bone (no children) at its parent joint's place. Such a bone has no
// direction, and when a whole chain is like that the rest pose folds the body up (a file
// whose joints were all moved onto their parents plays a 1.75 m avatar 0.58 m tall): for a
// skin joint with vertices skinned to it, an error. Without, it is an exporter's end marker (a leaf joint
// at its parent's place): a warning, and it does not make its parent zero-length.
// Lengths are compared with the bind mesh's size, so the file's units do not matter.
Result<void> check_bone_lengths(Builder& b, const MeshAsset& mesh) {
    const SkeletonAsset& s = b.skeleton;
    const std::size_t bones = s.size();
    std::vector<int> weighted(bones, 0);
    for (Eigen::Index j = 0; j < mesh.bone_weights.cols(); ++j)
        for (int k = 0; k < 4; ++k)
            if (mesh.bone_weights(k, j) > 0) ++weighted[static_cast<std::size_t>(mesh.bone_indices(k, j))];
    const Real size = (mesh.bind_positions.rowwise().maxCoeff() - mesh.bind_positions.rowwise().minCoeff()).norm();
    const Real zero = Real(1e-4) * size;
    std::vector<bool> has_children(bones, false);
    for (std::size_t i = 0; i < bones; ++i)
        if (s.parents[i] >= 0) has_children[static_cast<std::size_t>(s.parents[i])] = true;
    auto to_parent = [&](std::size_t i) {
        return (b.rest_global[i].translation() - b.rest_global[static_cast<std::size_t>(s.parents[i])].translation()).norm();
    };
    // An end marker: a leaf joint without vertices at its parent joint's place.
    auto end_marker = [&](std::size_t i) {
        return !has_children[i] && weighted[i] == 0 && s.parents[i] >= 0 && to_parent(i) <= zero;
    };
    std::vector<Real> length(bones, -1);  // -1: unknown (no informative child, no parent joint)
    for (std::size_t i = 0; i < bones; ++i) {
        if (s.parents[i] < 0 || end_marker(i)) continue;
        Real& l = length[static_cast<std::size_t>(s.parents[i])];
        l = std::max(l, to_parent(i));
    }
    std::string markers;
    int marker_count = 0;
    for (std::size_t i = 0; i < bones; ++i) {
        if (end_marker(i)) {
            if (b.has_bind[i] && ++marker_count <= 5) markers += (markers.empty() ? "'" : ", '") + s.bone_names[i] + "'";
            continue;
        }
        // Only skin joints: a mesh bound rigidly to a scene node (weight 1 on it) needs no direction.
        if (weighted[i] == 0 || !b.has_bind[i]) continue;
        bool end_bone = false;
        if (length[i] < 0) {  // no child joint that tells its length: the segment from its parent joint
            const int parent = s.parents[i];
            if (parent < 0 || !b.has_bind[static_cast<std::size_t>(parent)]) continue;  // hangs from a scene node
            length[i] = to_parent(i);
            end_bone = true;
        }
        if (length[i] > zero) continue;
        const std::string what = end_bone ? "an end bone at the joint of its parent '" +
                                                s.bone_names[static_cast<std::size_t>(s.parents[i])] + "'"
                                          : "its child joints sit at its own joint";
        return fail(b.at() + ": bone '" + s.bone_names[i] + "' has zero length in the rest pose (" + what + ") but " +
                    std::to_string(weighted[i]) + " vertices are skinned to it");
    }
    if (marker_count > 0)
        b.warnings.push_back(b.at() + ": " + std::to_string(marker_count) + " zero-length end bone" +
                             (marker_count > 1 ? "s" : "") + " without skinned vertices, ignored: " + markers +
                             (marker_count > 5 ? ", ..." : ""));
    return {};
}

Real rest_height(const SkeletonAsset& skeleton, const MeshAsset& mesh) {
    std::vector<Affine3> global, skinning;
    compose_pose(skeleton, skeleton.rest_local, global);
    skinning_matrices(skeleton, global, skinning);
    Matrix3X positions;
    skin_positions(mesh, skinning, Affine3::Identity(), positions);
    if (positions.cols() == 0) return 0;
    return positions.row(1).maxCoeff() - positions.row(1).minCoeff();
}

}  // namespace

Mat3 axes_to_drape(int up, int up_sign, int front, int front_sign, int coord, int coord_sign) {
    if (up < 0 || up > 2 || front < 0 || front > 2 || coord < 0 || coord > 2 || up == front || up == coord || front == coord)
        return Mat3::Identity();
    Mat3 m = Mat3::Zero();
    m(0, coord) = coord_sign < 0 ? -1 : 1;
    m(1, up) = up_sign < 0 ? -1 : 1;
    m(2, front) = front_sign < 0 ? -1 : 1;
    if (m.determinant() < 0) m.row(0) *= -1;  // keep it a rotation: the right axis follows from up and front
    return m;
}

Result<void> validate(const ImportOptions& o) {
    if (o.scale && !(std::isfinite(*o.scale) && *o.scale > 0)) return fail("scale: must be a finite number > 0");
    if (o.height_m && !(std::isfinite(*o.height_m) && *o.height_m > 0)) return fail("height_m: must be a finite number > 0");
    if (!(std::isfinite(o.fallback_height_m) && o.fallback_height_m > 0)) return fail("fallback_height_m: must be > 0");
    if (!(o.min_plausible_height_m > 0 && o.max_plausible_height_m > o.min_plausible_height_m))
        return fail("min/max_plausible_height_m: need 0 < min < max");
    return {};
}

void compute_clip_travel(AnimationClip& clip, const SkeletonAsset& skeleton) {
    clip.motion_bone = -1;
    clip.travel_m = clip.travel_local = Vec3::Zero();
    std::vector<int> depth(skeleton.size(), 0);
    for (std::size_t i = 0; i < skeleton.size(); ++i)
        depth[i] = skeleton.parents[i] < 0 ? 0 : depth[static_cast<std::size_t>(skeleton.parents[i])] + 1;
    const BoneChannel* best = nullptr;
    for (const BoneChannel& ch : clip.channels) {
        if (ch.positions.size() < 2 || ch.bone < 0 || ch.bone >= static_cast<int>(skeleton.size())) continue;
        Real spread = 0;
        for (const Vec3& p : ch.positions) spread = std::max(spread, (p - ch.positions.front()).norm());
        if (spread <= Real(1e-6) * std::max(Real(1), ch.positions.front().norm())) continue;
        if (best == nullptr || depth[static_cast<std::size_t>(ch.bone)] < depth[static_cast<std::size_t>(best->bone)]) best = &ch;
    }
    if (best == nullptr) return;
    std::vector<Affine3> global;
    compose_pose(skeleton, skeleton.rest_local, global);
    const int parent = skeleton.parents[static_cast<std::size_t>(best->bone)];
    const Affine3 to_model = parent < 0 ? Affine3::Identity() : global[static_cast<std::size_t>(parent)];
    Vec3 travel = to_model.linear() * (best->positions.back() - best->positions.front());
    travel.y() = 0;
    clip.motion_bone = best->bone;
    clip.travel_m = travel;
    clip.travel_local = to_model.linear().inverse() * travel;
}

Result<std::shared_ptr<const CharacterAsset>> import_character(const std::filesystem::path& path,
                                                               const ImportOptions& options) {
    if (auto ok = validate(options); !ok) return fail(where(path) + ": " + ok.error().message);
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return fail(where(path) + ": no such file");
    if (!std::filesystem::is_regular_file(path, ec)) return fail(where(path) + ": not a regular file");
    if (std::filesystem::file_size(path, ec) == 0) return fail(where(path) + ": empty file");

    Assimp::Importer importer;
    importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
    importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const aiScene* scene = importer.ReadFile(path.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                                                aiProcess_GenSmoothNormals | aiProcess_SortByPType |
                                                                aiProcess_ValidateDataStructure);
    if (scene == nullptr) {
        std::string why = one_line(importer.GetErrorString());
        if (why.find("mNumMeshes is 0") != std::string::npos)  // assimp's validation of a mesh-less scene
            return fail(where(path) + ": no meshes" + (path.extension() == ".bvh" ? " (a BVH file holds motion only)" : ""));
        return fail(where(path) + ": not a readable model (" + (why.empty() ? "unknown format" : why) + ")");
    }
    if (scene->mRootNode == nullptr || scene->mNumMeshes == 0) return fail(where(path) + ": no meshes");
    Builder b(path, scene);
    if (auto ok = build_skeleton(b); !ok) return std::unexpected(ok.error());
    if (options.require_animation && scene->mNumAnimations == 0) return fail(where(path) + ": no animation");
    collect_inverse_binds(b);
    auto mesh = std::make_shared<MeshAsset>();
    auto asset = std::make_shared<CharacterAsset>();
    if (auto ok = build_mesh(b, *mesh, asset->meshes); !ok) return std::unexpected(ok.error());
    if (auto ok = check_bone_lengths(b, *mesh); !ok) return std::unexpected(ok.error());

    std::vector<std::shared_ptr<AnimationClip>> clips;
    for (unsigned a = 0; a < scene->mNumAnimations; ++a) {
        auto clip = build_clip(b, scene->mAnimations[a], a);
        if (!clip) return std::unexpected(clip.error());
        if ((*clip)->duration_s <= 0 && options.require_animation && scene->mNumAnimations == 1)
            return fail(where(path) + ": clip '" + (*clip)->name + "' has no keys");
        clips.push_back(std::move(*clip));
    }

    SkeletonAsset& skeleton = b.skeleton;
    const std::size_t bones = skeleton.size();
    skeleton.rest_translation.resize(bones);
    skeleton.rest_rotation.resize(bones);
    skeleton.rest_scale.resize(bones);
    for (std::size_t i = 0; i < bones; ++i)
        decompose(skeleton.rest_local[i], skeleton.rest_translation[i], skeleton.rest_rotation[i], skeleton.rest_scale[i]);

    // Axes first, then units: the height is measured along Y.
    const Mat3 axes = source_format_contains(scene, "FBX") ? fbx_axes(scene) : Mat3::Identity();
    apply_root_correction(skeleton, *mesh, clips, axes, 1);
    const Real raw_height = rest_height(skeleton, *mesh);
    if (!(raw_height > 0) || !std::isfinite(raw_height)) return fail(where(path) + ": the rest pose has no height (flat or degenerate mesh)");
    double scale = 1;
    ScaleSource source = ScaleSource::file_units;
    const FileUnits units = file_units(scene, path);
    std::string note = units.stated;
    if (options.scale) {
        scale = *options.scale;
        source = ScaleSource::option;
    } else if (options.height_m) {
        scale = *options.height_m / raw_height;
        source = ScaleSource::height;
    } else {
        char text[256];
        if (units.metres_per_unit) {
            scale = *units.metres_per_unit;
            const double h = raw_height * scale;
            if (h < options.min_plausible_height_m || h > options.max_plausible_height_m) {
                // Some exporters state a unit their vertices do not use (the body would be
                // hundreds of metres tall): a standard height is nearer the truth.
                scale = options.fallback_height_m / raw_height;
                source = ScaleSource::fallback;
                std::snprintf(text, sizeof text, "; in that unit it is %.3g m tall, outside %.2g-%.2g m: scaled to %.2f m instead", h,
                              options.min_plausible_height_m, options.max_plausible_height_m, options.fallback_height_m);
                note += text;
            }
        } else {
            scale = options.fallback_height_m / raw_height;
            source = ScaleSource::fallback;
            std::snprintf(text, sizeof text, "; scaled to the standard height %.2f m", options.fallback_height_m);
            note += text;
        }
    }
    apply_root_correction(skeleton, *mesh, clips, Mat3::Identity(), static_cast<Real>(scale));
    if (!mesh->bind_positions.allFinite())
        return fail(where(path) + ": the bind pose is not finite (a singular node or bind matrix)");
    for (std::size_t i = 0; i < bones; ++i)
        if (!finite(skeleton.inverse_bind[i]) || !finite(skeleton.rest_local[i]))
            return fail(where(path) + ": bone '" + skeleton.bone_names[i] + "' has a singular or non-finite transform");
    for (auto& clip : clips) {
        compute_clip_travel(*clip, skeleton);
        blend_loop_seam(*clip);
    }

    std::vector<bool> moves(bones, false);
    for (Eigen::Index j = 0; j < mesh->bone_weights.cols(); ++j)
        for (int k = 0; k < 4; ++k)
            if (mesh->bone_weights(k, j) > 0) moves[static_cast<std::size_t>(mesh->bone_indices(k, j))] = true;

    asset->source = path;
    asset->name = path.stem().string();
    asset->scale = scale;
    asset->scale_source = source;
    asset->units_note = std::move(note);
    asset->height_m = rest_height(skeleton, *mesh);
    asset->skin_bones = static_cast<int>(std::count(moves.begin(), moves.end(), true));
    asset->warnings = std::move(b.warnings);
    asset->skeleton = std::make_shared<const SkeletonAsset>(std::move(skeleton));
    for (auto& clip : clips) asset->clips.push_back(std::move(clip));
    asset->mesh = std::move(mesh);
    return std::shared_ptr<const CharacterAsset>(std::move(asset));
}

Result<std::size_t> find_clip(const CharacterAsset& character, std::string_view name_or_index) {
    for (std::size_t i = 0; i < character.clips.size(); ++i)
        if (character.clips[i]->name == name_or_index) return i;
    // "Man_Walk" finds "HumanArmature|Man_Walk" (Blender's armature|action names) when unique.
    std::optional<std::size_t> suffix_match;
    int suffix_matches = 0;
    for (std::size_t i = 0; i < character.clips.size(); ++i) {
        const std::string& name = character.clips[i]->name;
        const auto bar = name.rfind('|');
        if (bar != std::string::npos && std::string_view(name).substr(bar + 1) == name_or_index) {
            suffix_match = i;
            ++suffix_matches;
        }
    }
    if (suffix_matches == 1) return *suffix_match;
    std::size_t index = 0;
    const char* end = name_or_index.data() + name_or_index.size();
    if (!name_or_index.empty()) {
        const auto [ptr, ec] = std::from_chars(name_or_index.data(), end, index);
        if (ec == std::errc() && ptr == end) {
            if (index < character.clips.size()) return index;
            return fail(where(character.source) + ": clip index " + std::string(name_or_index) + " is out of range (" +
                        std::to_string(character.clips.size()) + " clips)");
        }
    }
    std::string names;
    for (std::size_t i = 0; i < character.clips.size() && i < 20; ++i)
        names += (i ? ", '" : "'") + character.clips[i]->name + "'";
    if (character.clips.size() > 20) names += ", ...";
    return fail(where(character.source) + ": no clip named '" + std::string(name_or_index) + "' (clips: " +
                (names.empty() ? "none" : names) + ")");
}

namespace {

// The words of a clip name after its armature prefix ("HumanArmature|Man_Walk" -> man, walk;
// "WalkJump" -> walk, jump), lower case.
std::vector<std::string> clip_words(std::string_view name) {
    if (const auto bar = name.rfind('|'); bar != std::string_view::npos) name.remove_prefix(bar + 1);
    std::vector<std::string> words;
    std::string word;
    for (std::size_t i = 0; i < name.size(); ++i) {
        const char c = name[i];
        const bool letter = std::isalpha(static_cast<unsigned char>(c)) != 0;
        const bool upper_after_lower = letter && std::isupper(static_cast<unsigned char>(c)) && i > 0 &&
                                       std::islower(static_cast<unsigned char>(name[i - 1]));
        if (!letter || upper_after_lower) {
            if (!word.empty()) words.push_back(word);
            word.clear();
        }
        if (letter) word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    if (!word.empty()) words.push_back(word);
    return words;
}

// The first of `stems` (in their order) that starts one of the words, or empty.
std::string says(const std::vector<std::string>& words, std::initializer_list<std::string_view> stems) {
    for (std::string_view stem : stems)
        for (const std::string& w : words)
            if (w.rfind(stem, 0) == 0) return std::string(stem);
    return {};
}

}  // namespace

Real loop_mismatch_rad(const AnimationClip& clip) noexcept {
    Real worst = 0;
    for (const BoneChannel& ch : clip.channels)
        if (ch.rotations.size() >= 2) worst = std::max(worst, ch.rotations.front().angularDistance(ch.rotations.back()));
    return worst;
}

bool clip_loops(const AnimationClip& clip) noexcept {
    return !clip.channels.empty() && loop_mismatch_rad(clip) <= near_loop_tolerance_rad;
}

void blend_loop_seam(AnimationClip& clip) noexcept {
    clip.seam_blend_s = 0;
    if (!(clip.duration_s > 0) || !clip_loops(clip)) return;
    // Ends within a hundredth of a degree (and a micrometre) are on each other already.
    bool apart = loop_mismatch_rad(clip) > Real(2e-4);
    for (const BoneChannel& ch : clip.channels)
        if (ch.positions.size() >= 2) {
            Vec3 gap = ch.positions.front() - ch.positions.back();
            if (ch.bone == clip.motion_bone) gap += clip.travel_local;  // the travel is the cycle's, not a seam
            apart = apart || gap.norm() > Real(1e-6);
        }
    if (apart) clip.seam_blend_s = std::min(0.2, 0.2 * clip.duration_s);
}

std::optional<ClipChoice> choose_default_clip(const CharacterAsset& character) {
    if (character.clips.empty()) return std::nullopt;
    // Words that name another action than the one looked for ("WalkJump", "Walk_Back").
    const std::initializer_list<std::string_view> other_actions = {
        "jump", "turn", "back", "strafe", "crouch", "stop", "start", "death", "die", "punch", "attack", "sit", "injur", "limp"};
    struct Kind {
        std::initializer_list<std::string_view> stems;
        bool must_loop;
        const char* why;
    };
    const Kind kinds[] = {{{"walk"}, false, "name says "},
                          {{"run", "jog", "step", "stride", "march", "locomotion"}, true, "looping locomotion: name says "},
                          {{"idle", "breath"}, false, "no walk or locomotion clip; name says "}};
    for (const Kind& kind : kinds) {
        std::optional<std::size_t> best;
        int best_rank = 0;
        std::string best_word;
        for (std::size_t i = 0; i < character.clips.size(); ++i) {
            const AnimationClip& clip = *character.clips[i];
            const std::vector<std::string> words = clip_words(clip.name);
            const std::string word = says(words, kind.stems);
            if (word.empty()) continue;
            const bool looping = clip_loops(clip);
            if (kind.must_loop && !looping) continue;
            const int rank = (says(words, other_actions).empty() ? 2 : 0) + (looping ? 1 : 0);
            if (!best || rank > best_rank) {
                best = i;
                best_rank = rank;
                best_word = word;
            }
        }
        if (best) return ClipChoice{*best, character.clips[*best]->name + " (" + kind.why + best_word + ")", !kind.must_loop && &kind != &kinds[0]};
    }
    return ClipChoice{0, character.clips[0]->name + " (first clip: no walk, locomotion or idle clip)", true};
}

}  // namespace drape
