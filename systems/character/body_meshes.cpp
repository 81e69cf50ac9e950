// Which meshes of a character are its body: see body_meshes.hpp.
#include "drape/systems/character/body_meshes.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <limits>
#include <string_view>

#include "drape/engine/assets/skinning.hpp"

namespace drape {

namespace {

std::string lower(std::string_view text) {
    std::string out(text);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

// The garment word a name says, or empty.
std::string_view garment_word(std::string_view name) {
    static constexpr std::array<std::string_view, 10> words = {"dress", "skirt", "coat", "gown", "robe",
                                                               "cape", "cloak", "kilt", "apron", "tunic"};
    const std::string text = lower(name);
    for (std::string_view w : words)
        if (text.find(w) != std::string::npos) return w;
    return {};
}

bool in_subtree(const SkeletonAsset& s, int bone, int root) {
    for (int b = bone; b >= 0; b = s.parents[static_cast<std::size_t>(b)])
        if (b == root) return true;
    return false;
}

}  // namespace

std::vector<LeftOutMesh> find_non_body_meshes(const CharacterAsset& c, const BodyLandmarks& l) {
    std::vector<LeftOutMesh> out;
    if (!c.skeleton || !c.mesh || c.meshes.size() < 2) return out;
    const SkeletonAsset& s = *c.skeleton;
    const MeshAsset& m = *c.mesh;
    const std::size_t n = s.size();
    const Real h = l.height_m;

    // Bones each mesh moves (weight > 0), and how many meshes move each bone.
    std::vector<std::vector<char>> moves(c.meshes.size(), std::vector<char>(n, 0));
    std::vector<int> meshes_moving(n, 0);
    for (std::size_t k = 0; k < c.meshes.size(); ++k) {
        const MeshInfo& info = c.meshes[k];
        for (std::uint32_t v = info.first_vertex; v < info.first_vertex + info.vertex_count && v < m.vertex_count(); ++v)
            for (int slot = 0; slot < 4; ++slot)
                if (m.bone_weights(slot, v) > 0) moves[k][static_cast<std::size_t>(m.bone_indices(slot, v))] = 1;
        for (std::size_t b = 0; b < n; ++b) meshes_moving[b] += moves[k][b];
    }

    // The body's chains: the spine, what hangs from the head, each limb from the spine out
    // to its end, and the bones under a limb's end that move a mesh of several bones (the
    // fingers and toes of a skinned body, not a weapon's own bone).
    std::vector<char> chain(n, 0);
    for (int b : l.spine) chain[static_cast<std::size_t>(b)] = 1;
    std::vector<char> limb_end(n, 0);
    for (const LimbChain* limb : {&l.left_leg, &l.right_leg, &l.left_arm, &l.right_arm}) {
        if (limb->root < 0) continue;
        const int end = limb->end >= 0 ? limb->end : limb->middle >= 0 ? limb->middle : limb->root;
        limb_end[static_cast<std::size_t>(end)] = 1;
        for (int b = end; b >= 0 && !chain[static_cast<std::size_t>(b)]; b = s.parents[static_cast<std::size_t>(b)])
            chain[static_cast<std::size_t>(b)] = 1;
    }
    for (std::size_t b = 0; b < n; ++b) {
        if (l.head_bone >= 0 && in_subtree(s, static_cast<int>(b), l.head_bone)) chain[b] = 1;
        // A leg is all of its subtree (a foot, toes); nothing is held there.
        for (const LimbChain* leg : {&l.left_leg, &l.right_leg})
            if (leg->root >= 0 && in_subtree(s, static_cast<int>(b), leg->root)) chain[b] = 1;
        for (std::size_t e = 0; e < n; ++e)
            if (limb_end[e] && b != e && in_subtree(s, static_cast<int>(b), static_cast<int>(e))) {
                for (std::size_t k = 0; k < c.meshes.size(); ++k)
                    if (moves[k][b] && std::count(moves[k].begin(), moves[k].end(), 1) > 1) chain[b] = 1;
            }
    }

    // The skin at rest, for where a mesh is.
    std::vector<Affine3> global, skinning;
    compose_pose(s, s.rest_local, global);
    skinning_matrices(s, global, skinning);
    Matrix3X rest;
    skin_positions(m, skinning, Affine3::Identity(), rest);

    // The mesh carrying most of the head's skin is the body's own skin: never a garment.
    std::size_t skin_mesh = c.meshes.size();
    {
        std::size_t best = 0;
        for (std::size_t k = 0; k < c.meshes.size(); ++k) {
            std::size_t count = 0;
            const MeshInfo& info = c.meshes[k];
            for (std::uint32_t v = info.first_vertex; v < info.first_vertex + info.vertex_count && v < m.vertex_count(); ++v)
                if (l.head_bone >= 0 && m.bone_weights(0, v) > 0 && m.bone_indices(0, v) == l.head_bone) ++count;
            if (count > best) {
                best = count;
                skin_mesh = k;
            }
        }
    }

    const Vec3 hip_left = l.left_leg.root >= 0 ? Vec3(global[static_cast<std::size_t>(l.left_leg.root)].translation()) : Vec3::Zero();
    const Vec3 hip_right = l.right_leg.root >= 0 ? Vec3(global[static_cast<std::size_t>(l.right_leg.root)].translation()) : Vec3::Zero();
    const Vec3 mid = Real(0.5) * (hip_left + hip_right);
    const Real half_spacing = Real(0.5) * std::abs((hip_left - hip_right).dot(l.left));
    // Between the legs: from half way from the hip joints to the knees (below any
    // crotch: the skin's crotch itself may be a modelled skirt's hem) down to the knees.
    Real knee_m = l.floor_m + Real(0.28) * h;
    if (l.left_leg.middle >= 0 && l.right_leg.middle >= 0)
        knee_m = Real(0.5) * (global[static_cast<std::size_t>(l.left_leg.middle)].translation().y() +
                              global[static_cast<std::size_t>(l.right_leg.middle)].translation().y());
    const Real below_crotch_m = mid.y() - (mid.y() - knee_m) / 2;

    // The bone that moves each vertex most.
    std::vector<int> owner(m.vertex_count(), 0);
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        Eigen::Index best = 0;
        m.bone_weights.col(static_cast<Eigen::Index>(v)).maxCoeff(&best);
        owner[v] = m.bone_indices(best, static_cast<Eigen::Index>(v));
    }
    auto on_a_leg = [&](int bone) {
        return (l.left_leg.root >= 0 && in_subtree(s, bone, l.left_leg.root)) || (l.right_leg.root >= 0 && in_subtree(s, bone, l.right_leg.root));
    };
    // The lowest skin point of each leg.
    std::vector<Vec3> leg_lowest;
    {
        for (const LimbChain* leg : {&l.left_leg, &l.right_leg}) {
            if (leg->root < 0) continue;
            Eigen::Index lowest = -1;
            for (Eigen::Index v = 0; v < rest.cols(); ++v)
                if (in_subtree(s, owner[static_cast<std::size_t>(v)], leg->root) && (lowest < 0 || rest(1, v) < rest(1, lowest))) lowest = v;
            if (lowest >= 0) leg_lowest.push_back(rest.col(lowest));
        }
    }

    char text[256];
    for (std::size_t k = 0; k < c.meshes.size(); ++k) {
        const MeshInfo& info = c.meshes[k];
        if (info.vertex_count == 0) continue;
        // One bone for every vertex?
        int only = -1;
        for (std::size_t b = 0; b < n; ++b)
            if (moves[k][b]) only = only < 0 ? static_cast<int>(b) : -2;
        if (only >= 0) {
            const auto b = static_cast<std::size_t>(only);
            Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity()), hi = -lo;
            for (std::uint32_t v = info.first_vertex; v < info.first_vertex + info.vertex_count && v < rest.cols(); ++v) {
                lo = lo.cwiseMin(rest.col(v));
                hi = hi.cwiseMax(rest.col(v));
            }
            const Real size = (hi - lo).norm();
            const std::string& bone = s.bone_names[b];
            const char* what = info.rigid ? "not skinned, hangs from" : "skinned to";
            // A foot some rigs hang from the root (an IK foot): it comes within a tenth of the height of a leg's lowest skin.
            bool foot = false;
            for (const Vec3& ankle : leg_lowest)
                for (std::uint32_t v = info.first_vertex; !foot && v < info.first_vertex + info.vertex_count && v < rest.cols(); ++v)
                    foot = (Vec3(rest.col(v)) - ankle).norm() < Real(0.1) * h;
            if (!chain[b] && !foot && meshes_moving[b] == 1) {
                std::snprintf(text, sizeof text, "%s '%s' alone, a bone off the body's chains (a base, a prop)", what, bone.c_str());
                out.push_back({k, false, text});
                continue;
            }
            if (limb_end[b] && h > 0 && size > Real(0.3) * h) {
                std::snprintf(text, sizeof text, "%s '%s' alone, the end of a limb, and %.2f m across (held, not worn)", what,
                              bone.c_str(), double(size));
                out.push_back({k, false, text});
                continue;
            }
        }
        if (k == skin_mesh) continue;
        if (const std::string_view w = garment_word(info.name); !w.empty()) {
            out.push_back({k, true, "a modelled garment: its name says " + std::string(w)});
            continue;
        }
        if (const std::string_view w = garment_word(info.material); !w.empty()) {
            out.push_back({k, true, "a modelled garment: its material '" + info.material + "' says " + std::string(w)});
            continue;
        }
        // Cloth hanging between the legs, below the crotch, where no leg is.
        if (half_spacing > 0 && h > 0) {
            std::size_t between = 0;
            for (std::uint32_t v = info.first_vertex; v < info.first_vertex + info.vertex_count && v < rest.cols(); ++v) {
                const Vec3 p = rest.col(v);
                if (p.y() > below_crotch_m || p.y() < knee_m || on_a_leg(owner[v])) continue;  // trousers follow the thighs
                const Vec3 d = p - mid;
                if (std::abs(d.dot(l.left)) < Real(0.5) * half_spacing && std::abs(d.dot(l.forward)) < Real(0.3) * h)
                    ++between;
            }
            if (between >= 8 && between * 50 >= info.vertex_count) {
                std::snprintf(text, sizeof text, "a modelled garment: %zu of its vertices hang between the thighs moving with the trunk",
                              between);
                out.push_back({k, true, text});
            }
        }
    }
    return out;
}

CharacterAsset body_only(const CharacterAsset& character, const std::vector<LeftOutMesh>& left_out) {
    CharacterAsset out = character;
    if (left_out.empty() || !character.mesh) return out;
    const MeshAsset& m = *character.mesh;
    std::vector<char> drop(character.meshes.size(), 0);
    for (const LeftOutMesh& x : left_out)
        if (x.mesh < drop.size()) drop[x.mesh] = 1;
    std::vector<std::int64_t> new_index(m.vertex_count(), -1);
    Eigen::Index kept = 0;
    std::vector<MeshInfo> infos;
    for (std::size_t k = 0; k < character.meshes.size(); ++k) {
        if (drop[k]) continue;
        MeshInfo info = character.meshes[k];
        const std::uint32_t first = info.first_vertex;
        info.first_vertex = static_cast<std::uint32_t>(kept);
        for (std::uint32_t v = first; v < first + info.vertex_count && v < m.vertex_count(); ++v) new_index[v] = kept++;
        infos.push_back(info);
    }
    auto mesh = std::make_shared<MeshAsset>();
    mesh->bind_positions.resize(3, kept);
    mesh->bind_normals.resize(3, kept);
    mesh->bone_indices.resize(4, kept);
    mesh->bone_weights.resize(4, kept);
    for (Eigen::Index v = 0; v < static_cast<Eigen::Index>(m.vertex_count()); ++v) {
        const std::int64_t j = new_index[static_cast<std::size_t>(v)];
        if (j < 0) continue;
        mesh->bind_positions.col(j) = m.bind_positions.col(v);
        mesh->bind_normals.col(j) = m.bind_normals.col(v);
        mesh->bone_indices.col(j) = m.bone_indices.col(v);
        mesh->bone_weights.col(j) = m.bone_weights.col(v);
    }
    for (std::size_t k = 0; k < m.submeshes.size(); ++k) {
        if (k < drop.size() && drop[k]) continue;
        Submesh sub = m.submeshes[k];
        const std::uint32_t first = sub.first_index;
        sub.first_index = static_cast<std::uint32_t>(mesh->indices.size());
        for (std::uint32_t i = first; i < first + sub.index_count && i + 2 < m.indices.size(); i += 3) {
            const std::int64_t a = new_index[m.indices[i]], b = new_index[m.indices[i + 1]], c = new_index[m.indices[i + 2]];
            if (a < 0 || b < 0 || c < 0) continue;
            mesh->indices.insert(mesh->indices.end(), {static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b), static_cast<std::uint32_t>(c)});
        }
        sub.index_count = static_cast<std::uint32_t>(mesh->indices.size()) - sub.first_index;
        mesh->submeshes.push_back(sub);
    }
    out.meshes = std::move(infos);
    out.mesh = std::move(mesh);
    if (kept > 0 && out.skeleton) {
        std::vector<Affine3> global, skinning;
        compose_pose(*out.skeleton, out.skeleton->rest_local, global);
        skinning_matrices(*out.skeleton, global, skinning);
        Matrix3X rest;
        skin_positions(*out.mesh, skinning, Affine3::Identity(), rest);
        out.height_m = rest.row(1).maxCoeff() - rest.row(1).minCoeff();
    }
    return out;
}

}  // namespace drape
