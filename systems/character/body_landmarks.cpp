// Body landmarks from skeleton and skin: see body_landmarks.hpp.
#include "drape/systems/character/body_landmarks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "drape/engine/assets/skinning.hpp"
#include "drape/systems/character/ellipsoid_fit.hpp"

namespace drape {

namespace {

using Vec2d = Eigen::Vector2d;

struct Rig {
    const SkeletonAsset& skeleton;
    std::vector<std::vector<int>> children;
    std::vector<Affine3> global;  // rest, bone -> model
    Matrix3X positions;           // skin at rest, model space
    std::vector<int> owner;       // dominant bone per vertex
    std::vector<Real> reach_low, reach_high, reach_side;  // per subtree: lowest/highest skin or joint, widest off the trunk
};

Vec3 joint(const Rig& rig, int b) { return rig.global[static_cast<std::size_t>(b)].translation(); }

bool in_subtree(const Rig& rig, int bone, int root) {
    for (int b = bone; b >= 0; b = rig.skeleton.parents[static_cast<std::size_t>(b)])
        if (b == root) return true;
    return false;
}

// Per subtree: lowest and highest point (joints and the skin each bone dominates), and
// the farthest horizontal distance from `axis`.
void measure_subtrees(Rig& rig, const Vec3& axis) {
    const std::size_t n = rig.skeleton.size();
    rig.reach_low.assign(n, std::numeric_limits<Real>::infinity());
    rig.reach_high.assign(n, -std::numeric_limits<Real>::infinity());
    rig.reach_side.assign(n, 0);
    auto add = [&](std::size_t b, const Vec3& p) {
        rig.reach_low[b] = std::min(rig.reach_low[b], p.y());
        rig.reach_high[b] = std::max(rig.reach_high[b], p.y());
        rig.reach_side[b] = std::max(rig.reach_side[b], Vec3(p.x() - axis.x(), 0, p.z() - axis.z()).norm());
    };
    for (std::size_t b = 0; b < n; ++b) add(b, joint(rig, static_cast<int>(b)));
    for (Eigen::Index v = 0; v < rig.positions.cols(); ++v) add(static_cast<std::size_t>(rig.owner[static_cast<std::size_t>(v)]), rig.positions.col(v));
    for (std::size_t b = n; b-- > 0;) {  // parents come first: children fold into parents
        const int p = rig.skeleton.parents[b];
        if (p < 0) continue;
        const auto q = static_cast<std::size_t>(p);
        rig.reach_low[q] = std::min(rig.reach_low[q], rig.reach_low[b]);
        rig.reach_high[q] = std::max(rig.reach_high[q], rig.reach_high[b]);
        rig.reach_side[q] = std::max(rig.reach_side[q], rig.reach_side[b]);
    }
}

// A chain from `root` down its subtree, following the child whose subtree reaches lowest
// (legs) or farthest sideways (arms); up to three bones that move skin.
LimbChain follow_chain(const Rig& rig, int root, bool down) {
    std::vector<int> chain;
    for (int b = root; b >= 0 && chain.size() < 8;) {
        chain.push_back(b);
        int next = -1;
        for (int c : rig.children[static_cast<std::size_t>(b)]) {
            const auto cc = static_cast<std::size_t>(c);
            if (next < 0 || (down ? rig.reach_low[cc] < rig.reach_low[static_cast<std::size_t>(next)]
                                  : rig.reach_side[cc] > rig.reach_side[static_cast<std::size_t>(next)]))
                next = c;
        }
        b = next;
    }
    // Bones that carry skin; a short bone without skin (a twist or end bone) is skipped.
    std::vector<int> skinned;
    std::vector<std::size_t> count(rig.skeleton.size(), 0);
    for (int o : rig.owner) ++count[static_cast<std::size_t>(o)];
    for (int b : chain)
        if (count[static_cast<std::size_t>(b)] > 0) skinned.push_back(b);
    LimbChain out;
    if (!skinned.empty()) out.root = skinned[0];
    if (skinned.size() > 1) out.middle = skinned[1];
    if (skinned.size() > 2) out.end = skinned[2];
    if (out.root < 0) out.root = root;
    return out;
}

// Convex hull (monotone chain) of 2D points; returns its vertices counter-clockwise.
std::vector<Vec2d> convex_hull(std::vector<Vec2d> p) {
    std::sort(p.begin(), p.end(), [](const Vec2d& a, const Vec2d& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); });
    if (p.size() < 3) return p;
    std::vector<Vec2d> h(2 * p.size());
    std::size_t k = 0;
    auto cross = [](const Vec2d& o, const Vec2d& a, const Vec2d& b) {
        return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
    };
    for (std::size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
        h[k++] = p[i];
    }
    for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
        h[k++] = p[i];
    }
    h.resize(k - 1);
    return h;
}

// Where the edge a-b crosses the horizontal plane at height `y`, if it does.
std::optional<Vec3> crossing(const Vec3& a, const Vec3& b, Real y) {
    if ((a.y() - y) * (b.y() - y) > 0 || a.y() == b.y()) return std::nullopt;
    return a + ((y - a.y()) / (b.y() - a.y())) * (b - a);
}

struct Cut {
    bool valid = false;
    Vec3 center = Vec3::Zero();
    Real half_width = 0, half_depth = 0, girth = 0;
};

// The section of the skin of `bones` (a mask) at height `y`.
Cut section(const Rig& rig, const std::vector<std::uint32_t>& indices, const std::vector<char>& bones, Real y,
            const Vec3& left, const Vec3& forward, Real left_min = -std::numeric_limits<Real>::infinity(),
            Real left_max = std::numeric_limits<Real>::infinity()) {
    std::vector<Vec2d> points;  // (left, forward) coordinates
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
        const std::uint32_t v[3] = {indices[t], indices[t + 1], indices[t + 2]};
        bool ours = true;
        for (std::uint32_t i : v) ours = ours && bones[static_cast<std::size_t>(rig.owner[i])];
        if (!ours) continue;
        for (int e = 0; e < 3; ++e) {
            const std::optional<Vec3> at = crossing(rig.positions.col(v[e]), rig.positions.col(v[(e + 1) % 3]), y);
            if (!at) continue;
            const Vec3& p = *at;
            if (p.dot(left) < left_min || p.dot(left) > left_max) continue;  // beyond the armpits: an arm
            points.emplace_back(double(p.dot(left)), double(p.dot(forward)));
        }
    }
    Cut cut;
    const std::vector<Vec2d> hull = convex_hull(points);
    if (hull.size() < 3) return cut;
    Vec2d lo = hull[0], hi = hull[0];
    for (std::size_t i = 0; i < hull.size(); ++i) {
        cut.girth += Real((hull[(i + 1) % hull.size()] - hull[i]).norm());
        lo = lo.cwiseMin(hull[i]);
        hi = hi.cwiseMax(hull[i]);
    }
    const Vec2d c = 0.5 * (lo + hi);
    cut.center = left * Real(c.x()) + forward * Real(c.y()) + Vec3::UnitY() * y;
    cut.half_width = Real(0.5 * (hi.x() - lo.x()));
    cut.half_depth = Real(0.5 * (hi.y() - lo.y()));
    cut.valid = true;
    return cut;
}

// Distance between two segments of the plane.
double segment_distance(const Vec2d& a, const Vec2d& b, const Vec2d& c, const Vec2d& d) {
    const auto cross = [](const Vec2d& p, const Vec2d& q) { return p.x() * q.y() - p.y() * q.x(); };
    if (cross(b - a, c - a) * cross(b - a, d - a) < 0 && cross(d - c, a - c) * cross(d - c, b - c) < 0) return 0;
    const auto to_segment = [](const Vec2d& p, const Vec2d& s0, const Vec2d& s1) {
        const Vec2d e = s1 - s0;
        const double t = e.squaredNorm() > 0 ? std::clamp((p - s0).dot(e) / e.squaredNorm(), 0.0, 1.0) : 0.0;
        return (s0 + t * e - p).norm();
    };
    return std::min({to_segment(a, c, d), to_segment(b, c, d), to_segment(c, a, b), to_segment(d, a, b)});
}

// The skin's section at height `y` on one side of the body (`sign` along `left` from
// `origin`), as segments in the (across, forward) plane, joined into pieces where they come
// within `gap` of each other: whether a piece lies beyond the one over the body's middle (an
// arm hanging apart from the trunk), and how far the middle piece reaches (along `left`
// times `sign`, from `origin`).
struct SideGap {
    bool gap = false;
    Real trunk_end = 0;
};
SideGap side_gap(const Rig& rig, const std::vector<std::uint32_t>& indices, Real y, const Vec3& left, const Vec3& forward,
                 const Vec3& origin, Real sign, Real gap) {
    std::vector<std::array<Vec2d, 2>> segments;
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
        std::array<Vec2d, 2> s;
        int found = 0;
        for (int e = 0; e < 3 && found < 2; ++e) {
            const std::optional<Vec3> at = crossing(rig.positions.col(indices[t + static_cast<std::size_t>(e)]),
                                                    rig.positions.col(indices[t + static_cast<std::size_t>((e + 1) % 3)]), y);
            if (!at) continue;
            const Vec3 q = *at - origin;
            s[static_cast<std::size_t>(found++)] = Vec2d(double(sign * q.dot(left)), double(q.dot(forward)));
        }
        if (found == 2 && std::max(s[0].x(), s[1].x()) >= 0) segments.push_back(s);
    }
    SideGap out;
    const std::size_t k = segments.size();
    if (k == 0) return out;
    std::vector<std::size_t> parent(k);
    for (std::size_t i = 0; i < k; ++i) parent[i] = i;
    const auto root = [&](std::size_t i) {
        while (parent[i] != i) i = parent[i] = parent[parent[i]];
        return i;
    };
    for (std::size_t i = 0; i < k; ++i)
        for (std::size_t j = i + 1; j < k; ++j)
            if (root(i) != root(j) && segment_distance(segments[i][0], segments[i][1], segments[j][0], segments[j][1]) <= double(gap))
                parent[root(i)] = root(j);
    // The middle piece: the one reaching nearest the middle of the body.
    std::size_t middle = 0;
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < k; ++i) {
        const double u = std::min(segments[i][0].x(), segments[i][1].x());
        if (u < nearest) nearest = u, middle = root(i);
    }
    double end = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < k; ++i)
        if (root(i) == middle) end = std::max({end, segments[i][0].x(), segments[i][1].x()});
    for (std::size_t i = 0; i < k && !out.gap; ++i)
        out.gap = root(i) != middle && std::max(segments[i][0].x(), segments[i][1].x()) > end;
    out.trunk_end = Real(end);
    return out;
}

BodyPoint body_point(const Rig& rig, int bone, const Vec3& rest) {
    BodyPoint p;
    p.bone = bone;
    p.rest_m = rest;
    if (bone >= 0) p.local_m = rigid_part(rig.global[static_cast<std::size_t>(bone)]).inverse(Eigen::Isometry) * rest;
    return p;
}

// The spine bone that carries a point at height `y`: the highest whose joint is not above it.
int spine_bone_at(const Rig& rig, const std::vector<int>& spine, Real y) {
    int best = spine.front();
    for (int b : spine)
        if (joint(rig, b).y() <= y) best = b;
    return best;
}

}  // namespace

Result<BodyLandmarks> find_body_landmarks(const CharacterAsset& character) {
    const std::string at = character.source.string() + ": body landmarks: ";
    if (!character.skeleton || !character.mesh || character.mesh->vertex_count() == 0)
        return fail(at + "no skeleton or skin");
    const SkeletonAsset& skeleton = *character.skeleton;
    const MeshAsset& mesh = *character.mesh;
    Rig rig{skeleton, {}, {}, {}, dominant_bones(mesh), {}, {}, {}};
    const std::size_t n = skeleton.size();
    rig.children.resize(n);
    for (std::size_t b = 0; b < n; ++b)
        if (skeleton.parents[b] >= 0) rig.children[static_cast<std::size_t>(skeleton.parents[b])].push_back(static_cast<int>(b));
    std::vector<Affine3> skinning;
    compose_pose(skeleton, skeleton.rest_local, rig.global);
    skinning_matrices(skeleton, rig.global, skinning);
    Matrix3X normals;
    skin_mesh(mesh, skinning, Affine3::Identity(), rig.positions, normals);
    if (!rig.positions.allFinite()) return fail(at + "the skin at the rest pose is not finite");

    const Real all_low = rig.positions.row(1).minCoeff(), all_high = rig.positions.row(1).maxCoeff();
    const Real all_height = all_high - all_low;
    if (!(all_height > 0)) return fail(at + "the skin is flat");
    Vec3 axis = rig.positions.rowwise().mean();
    measure_subtrees(rig, axis);

    // Pelvis: a named one, else the highest bone with two children whose skin reaches the floor.
    BodyLandmarks out;
    auto reaches_floor = [&](int c) { return rig.reach_low[static_cast<std::size_t>(c)] < all_low + Real(0.2) * all_height; };
    // A leg hangs from its bone's joint to the floor and does not rise above it; the
    // pelvis also carries a chain that reaches the top (the spine).
    auto floor_children = [&](int b) {
        std::vector<int> legs;
        const Real at = joint(rig, b).y();
        for (int c : rig.children[static_cast<std::size_t>(b)])
            if (reaches_floor(c) && joint(rig, c).y() <= at + Real(0.05) * all_height &&
                rig.reach_high[static_cast<std::size_t>(c)] < at + Real(0.15) * all_height)
                legs.push_back(c);
        bool spine = false;
        for (int c : rig.children[static_cast<std::size_t>(b)])
            spine = spine || rig.reach_high[static_cast<std::size_t>(c)] > all_high - Real(0.25) * all_height;
        if (!spine) legs.clear();
        return legs;
    };
    int pelvis = -1;
    for (std::size_t b = 0; b < n; ++b)
        if (region_from_bone_name(skeleton.bone_names[b]) == BodyRegion::pelvis && floor_children(static_cast<int>(b)).size() >= 2) {
            pelvis = static_cast<int>(b);
            out.found_by = "bone names";
            break;
        }
    if (pelvis < 0) {
        for (std::size_t b = 0; b < n; ++b)
            if (floor_children(static_cast<int>(b)).size() >= 2 && (pelvis < 0 || joint(rig, static_cast<int>(b)).y() > joint(rig, pelvis).y()))
                pelvis = static_cast<int>(b);
        out.found_by = "topology";
    }
    if (pelvis < 0) return fail(at + "no bone with two legs hanging from it (not a humanoid)");
    out.pelvis_bone = pelvis;

    // Legs: the two children reaching lowest. Spine: the child reaching highest, up to the top.
    std::vector<int> legs = floor_children(pelvis);
    std::sort(legs.begin(), legs.end(), [&](int a, int b) { return rig.reach_low[static_cast<std::size_t>(a)] < rig.reach_low[static_cast<std::size_t>(b)]; });
    legs.resize(2);
    int up_child = -1;
    for (int c : rig.children[static_cast<std::size_t>(pelvis)])
        if (c != legs[0] && c != legs[1] && (up_child < 0 || rig.reach_high[static_cast<std::size_t>(c)] > rig.reach_high[static_cast<std::size_t>(up_child)]))
            up_child = c;
    if (up_child < 0 || rig.reach_high[static_cast<std::size_t>(up_child)] < joint(rig, pelvis).y() + Real(0.2) * all_height)
        return fail(at + "no spine above the pelvis '" + skeleton.bone_names[static_cast<std::size_t>(pelvis)] + "'");
    out.spine.push_back(pelvis);
    for (int b = up_child; b >= 0;) {
        out.spine.push_back(b);
        int next = -1;
        for (int c : rig.children[static_cast<std::size_t>(b)])
            if (next < 0 || rig.reach_high[static_cast<std::size_t>(c)] > rig.reach_high[static_cast<std::size_t>(next)]) next = c;
        b = next;
    }

    // Axis of the trunk: the pelvis joint. Arms: off the spine bone with two children
    // reaching farthest sideways.
    axis = joint(rig, pelvis);
    measure_subtrees(rig, axis);
    std::vector<int> arms;
    for (int s : out.spine) {
        if (s == pelvis) continue;
        std::vector<int> side;
        for (int c : rig.children[static_cast<std::size_t>(s)]) {
            if (std::find(out.spine.begin(), out.spine.end(), c) != out.spine.end()) continue;
            if (rig.reach_side[static_cast<std::size_t>(c)] > Real(0.15) * all_height) side.push_back(c);
        }
        if (side.size() >= 2) {
            std::sort(side.begin(), side.end(), [&](int a, int b) { return rig.reach_side[static_cast<std::size_t>(a)] > rig.reach_side[static_cast<std::size_t>(b)]; });
            arms = {side[0], side[1]};
            out.chest_bone = s;
            break;
        }
    }
    if (arms.empty()) return fail(at + "no two arms hang from the spine above '" + skeleton.bone_names[static_cast<std::size_t>(pelvis)] + "'");
    out.head_bone = out.spine.back();
    // The spine stops at the head's bone with skin: drop end bones that move no skin.
    {
        std::vector<std::size_t> count(n, 0);
        for (int o : rig.owner) ++count[static_cast<std::size_t>(o)];
        while (out.spine.size() > 2 && count[static_cast<std::size_t>(out.spine.back())] == 0) out.spine.pop_back();
        out.head_bone = out.spine.back();
    }

    // Body bones and vertices: the pelvis's subtree, and bones that are neither its
    // ancestors nor in it (feet bound to the root) whose skin is below the pelvis.
    std::vector<char> is_body(n, 0), is_ancestor(n, 0);
    for (int b = skeleton.parents[static_cast<std::size_t>(pelvis)]; b >= 0; b = skeleton.parents[static_cast<std::size_t>(b)]) is_ancestor[static_cast<std::size_t>(b)] = 1;
    for (std::size_t b = 0; b < n; ++b) {
        if (in_subtree(rig, static_cast<int>(b), pelvis)) is_body[b] = 1;
        else if (!is_ancestor[b] && rig.reach_high[b] < joint(rig, pelvis).y()) is_body[b] = 1;
    }
    Real floor = std::numeric_limits<Real>::infinity(), top = -floor;
    for (Eigen::Index v = 0; v < rig.positions.cols(); ++v) {
        if (!is_body[static_cast<std::size_t>(rig.owner[static_cast<std::size_t>(v)])]) continue;
        floor = std::min(floor, rig.positions(1, v));
        top = std::max(top, rig.positions(1, v));
    }
    for (std::size_t b = 0; b < n; ++b)
        if (is_body[b]) out.body_bones.push_back(static_cast<int>(b));
    out.floor_m = floor;
    out.top_m = top;
    out.height_m = top - floor;
    const Real h = out.height_m;
    if (!(h > 0)) return fail(at + "the body has no height");

    // Forward: across the line through the hip joints, on the side of model +Z (glTF's and
    // FBX's front once imported Y up); a foot's shape is too varied to tell toes from heel.
    Vec3 across = joint(rig, legs[0]) - joint(rig, legs[1]);
    across.y() = 0;
    if (!(across.norm() > Real(0.01) * h)) return fail(at + "the two legs hang from one place");
    Vec3 forward = Vec3::UnitY().cross(across.normalized());
    if (forward.z() < 0) forward = -forward;
    out.forward = forward;
    out.left = out.up.cross(forward).normalized();

    // Sides from geometry.
    auto side_of = [&](int b) { return (joint(rig, b) - axis).dot(out.left); };
    if (side_of(legs[0]) < side_of(legs[1])) std::swap(legs[0], legs[1]);
    if (side_of(arms[0]) < side_of(arms[1])) std::swap(arms[0], arms[1]);
    out.left_leg = follow_chain(rig, legs[0], true);
    out.right_leg = follow_chain(rig, legs[1], true);
    out.left_arm = follow_chain(rig, arms[0], false);
    out.right_arm = follow_chain(rig, arms[1], false);

    // Trunk bones: the spine below the head, not the arms' or legs' subtrees.
    std::vector<char> trunk(n, 0), trunk_and_thighs(n, 0), arm(n, 0);
    for (int s : out.spine)
        if (s != out.head_bone) trunk[static_cast<std::size_t>(s)] = 1;
    // A neck bone between chest and head is not trunk.
    for (std::size_t i = 0; i < out.spine.size(); ++i)
        if (out.chest_bone >= 0 && i > 0 && out.spine[i - 1] == out.chest_bone) {
            for (std::size_t j = i; j < out.spine.size(); ++j) trunk[static_cast<std::size_t>(out.spine[j])] = 0;
            break;
        }
    for (std::size_t b = 0; b < n; ++b) {
        if (in_subtree(rig, static_cast<int>(b), arms[0]) || in_subtree(rig, static_cast<int>(b), arms[1])) arm[b] = 1;
        trunk_and_thighs[b] = trunk[b];
    }
    for (int leg : legs) trunk_and_thighs[static_cast<std::size_t>(follow_chain(rig, leg, true).root)] = 1;
    for (int leg : legs) trunk_and_thighs[static_cast<std::size_t>(leg)] = 1;

    // Crotch: where the legs part, the lowest point at which the midplane between the two
    // thighs' joints still cuts the skin, within the trunk's depth, above the knees (whatever
    // bone the skin there follows: in many rigs it is a thigh's). Else the lowest skin of the
    // pelvis bone near the midplane; else under the pelvis joint.
    Real crotch = std::numeric_limits<Real>::infinity();
    const Vec3 between = Real(0.5) * (joint(rig, out.left_leg.root) + joint(rig, out.right_leg.root));
    const Real knees = std::max(out.left_leg.middle >= 0 ? joint(rig, out.left_leg.middle).y() : -std::numeric_limits<Real>::infinity(),
                                out.right_leg.middle >= 0 ? joint(rig, out.right_leg.middle).y() : -std::numeric_limits<Real>::infinity());
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
        for (std::size_t e = 0; e < 3; ++e) {
            const Vec3 a = rig.positions.col(mesh.indices[t + e]), b = rig.positions.col(mesh.indices[t + (e + 1) % 3]);
            const Real sa = (a - between).dot(out.left), sb = (b - between).dot(out.left);
            if (!(sa * sb < 0)) continue;
            const Vec3 q = a + (b - a) * (sa / (sa - sb));
            if (q.y() > knees + Real(0.02) * h && std::abs((q - between).dot(out.forward)) < Real(0.15) * h) crotch = std::min(crotch, q.y());
        }
    const bool crotch_parted = std::isfinite(crotch) && crotch < joint(rig, pelvis).y() + Real(0.1) * h;
    bool crotch_on_skin = false;
    if (!crotch_parted) {
        crotch = std::numeric_limits<Real>::infinity();
        for (Eigen::Index v = 0; v < rig.positions.cols(); ++v) {
            if (rig.owner[static_cast<std::size_t>(v)] != pelvis) continue;
            if (std::abs((Vec3(rig.positions.col(v)) - axis).dot(out.left)) > Real(0.02) * h) continue;
            crotch = std::min(crotch, rig.positions(1, v));
        }
        crotch_on_skin = std::isfinite(crotch) && crotch <= joint(rig, pelvis).y();
        if (!crotch_on_skin) crotch = joint(rig, pelvis).y() - Real(0.05) * h;
    }
    out.crotch_m = crotch;

    // Armpits, from the skin's shape: scanning down from the shoulder, the first height at
    // which the skin's section across the body parts into the trunk and an arm hanging
    // beside it (the gap opens under the armpit), refined to a millimetre. Else (an arm held
    // out, or touching the trunk all the way down) the lowest arm skin on a triangle shared
    // with the trunk.
    const std::vector<std::uint32_t>& indices = mesh.indices;
    std::array<Real, 2> gap_armpit{std::numeric_limits<Real>::quiet_NaN(), std::numeric_limits<Real>::quiet_NaN()};
    std::array<Real, 2> gap_side{0, 0};
    for (int s = 0; s < 2; ++s) {
        const LimbChain& chain = s == 0 ? out.left_arm : out.right_arm;
        const Real sign = s == 0 ? Real(1) : Real(-1);
        Real top = joint(rig, chain.root).y();
        if (chain.middle >= 0) top = std::max(top, joint(rig, chain.middle).y());
        const Real step = Real(0.0025) * h, gap = Real(0.001) * h, bottom = crotch + Real(0.1) * h;
        for (Real y = top; y > bottom; y -= step) {
            SideGap g = side_gap(rig, indices, y, out.left, out.forward, axis, sign, gap);
            if (!g.gap) continue;
            Real joined = y + step;  // refine between the parted height and the one above it
            for (int i = 0; i < 8 && joined - y > Real(0.0005) * h; ++i) {
                const Real mid = Real(0.5) * (y + joined);
                const SideGap m = side_gap(rig, indices, mid, out.left, out.forward, axis, sign, gap);
                if (m.gap) y = mid, g = m;
                else joined = mid;
            }
            gap_armpit[static_cast<std::size_t>(s)] = Real(0.5) * (y + joined);
            gap_side[static_cast<std::size_t>(s)] = axis.dot(out.left) + sign * g.trunk_end;
            break;
        }
    }
    const bool armpits_by_shape = std::isfinite(gap_armpit[0]) && std::isfinite(gap_armpit[1]);
    std::array<Real, 2> armpit{std::numeric_limits<Real>::infinity(), std::numeric_limits<Real>::infinity()};
    std::array<Real, 2> armpit_side{0, 0};  // along `left`: where each armpit is across the body
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
        bool touches_trunk = false;
        for (int e = 0; e < 3; ++e) touches_trunk = touches_trunk || trunk[static_cast<std::size_t>(rig.owner[indices[t + static_cast<std::size_t>(e)]])];
        if (!touches_trunk) continue;
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t v = indices[t + static_cast<std::size_t>(e)];
            const int o = rig.owner[v];
            if (!arm[static_cast<std::size_t>(o)]) continue;
            const int s = in_subtree(rig, o, arms[0]) ? 0 : 1;
            if (rig.positions(1, v) < armpit[static_cast<std::size_t>(s)]) {
                armpit[static_cast<std::size_t>(s)] = rig.positions(1, v);
                armpit_side[static_cast<std::size_t>(s)] = Vec3(rig.positions.col(v)).dot(out.left);
            }
        }
    }
    int armpits_on_skin = 0;
    for (int s = 0; s < 2; ++s) {
        const Real shoulder = joint(rig, (s == 0 ? out.left_arm : out.right_arm).root).y();
        Real& a = armpit[static_cast<std::size_t>(s)];
        if (!std::isfinite(a) || a > shoulder || a < shoulder - Real(0.15) * h) a = shoulder - Real(0.06) * h;
        else ++armpits_on_skin;
    }
    // Where the arms' skin reaches lowest on the trunk: the waist is looked for below it,
    // and the built-in dress is held under it (arms_meet_trunk).
    const Real arms_skin = Real(0.5) * (armpit[0] + armpit[1]);
    if (armpits_by_shape) {
        armpit = gap_armpit;
        armpit_side = gap_side;
        armpits_on_skin = 2;
    }
    // The higher armpit: an arm modelled against the trunk parts from it lower than the
    // armpit on its side (Male_Casual's and Male_LongSleeve's 5.7 cm lower than the other
    // side), never higher, and a body's two armpits are at one height.
    out.underarm_m = std::max(armpit[0], armpit[1]);
    // Shoulders: the upper arm's head, the first joint of the arm's chain (from the trunk
    // out) above its armpit and as far out as the trunk's side there (a clavicle's joint by
    // the neck is not); else the chain's first joint.
    for (int s = 0; s < 2; ++s) {
        const LimbChain& chain = s == 0 ? out.left_arm : out.right_arm;
        const Real sign = s == 0 ? Real(1) : Real(-1);
        int head = chain.root;
        if (armpits_by_shape)
            for (int b : {chain.root, chain.middle, chain.end}) {
                if (b < 0) continue;
                const Vec3 j = joint(rig, b);
                if (j.y() > armpit[static_cast<std::size_t>(s)] &&
                    sign * (j.dot(out.left) - armpit_side[static_cast<std::size_t>(s)]) >= -Real(0.01) * h) {
                    head = b;
                    break;
                }
            }
        (s == 0 ? out.left_shoulder : out.right_shoulder) = body_point(rig, head, joint(rig, head));
    }
    if (!(out.underarm_m > crotch + Real(0.1) * h))
        return fail(at + "the armpits are not above the crotch by a tenth of the height");

    // Sections.
    auto make_section = [&](const Cut& c) {
        BodySection s;
        s.center = body_point(rig, spine_bone_at(rig, out.spine, c.center.y()), c.center);
        s.half_width_m = c.half_width;
        s.half_depth_m = c.half_depth;
        s.girth_m = c.girth;
        return s;
    };
    auto extreme = [&](const std::vector<char>& bones, Real from, Real to, bool narrowest) {
        Cut best;
        constexpr int samples = 24;
        for (int i = 0; i <= samples; ++i) {
            const Real y = from + (to - from) * Real(i) / samples;
            const Cut c = section(rig, indices, bones, y, out.left, out.forward);
            if (!c.valid) continue;
            if (!best.valid || (narrowest ? c.girth < best.girth : c.girth > best.girth)) best = c;
        }
        return best;
    };
    const Real span = arms_skin - crotch;
    const Cut waist = extreme(trunk_and_thighs, crotch + Real(0.3) * span, crotch + Real(0.8) * span, true);
    if (!waist.valid) return fail(at + "the trunk's skin has no section between crotch and armpits");
    // The hips: the fullest section of the trunk with the thighs between crotch and waist;
    // where the girth is within 1 % of the fullest over a stretch (the thighs' hull bridging
    // the gap between them just above the crotch), the highest section of that plateau.
    Cut hips;
    {
        constexpr int samples = 24;
        std::vector<Cut> cuts;
        Real fullest = 0;
        for (int i = 0; i <= samples; ++i) {
            const Cut c = section(rig, indices, trunk_and_thighs, crotch + (waist.center.y() - crotch) * Real(i) / samples, out.left, out.forward);
            if (!c.valid) continue;
            cuts.push_back(c);
            fullest = std::max(fullest, c.girth);
        }
        for (const Cut& c : cuts)
            if (c.girth >= Real(0.98) * fullest) hips = c;
    }
    // The chest: the trunk, and the skin of the arms' first bones (a clavicle's, over the
    // upper chest) between the armpits, where it is chest, not arm.
    Cut chest;
    bool chest_flat = false;
    {
        std::vector<char> chest_bones = trunk;
        for (const LimbChain* a : {&out.left_arm, &out.right_arm}) chest_bones[static_cast<std::size_t>(a->root)] = 1;
        const bool sides = armpits_on_skin == 2 && armpit_side[0] > armpit_side[1];
        // The bust or the pectorals: the section whose front reaches farthest forward.
        const auto front = [&](const Cut& k) { return k.center.dot(out.forward) + k.half_depth; };
        constexpr int samples = 24;
        std::vector<Cut> cuts;
        for (int i = 0; i <= samples; ++i) {
            const Real y = waist.center.y() + (out.underarm_m - waist.center.y()) * Real(i) / samples;
            const Cut c = sides ? section(rig, indices, chest_bones, y, out.left, out.forward, armpit_side[1], armpit_side[0])
                                : section(rig, indices, trunk, y, out.left, out.forward);
            if (c.valid && (!chest.valid || front(c) > front(chest))) chest = c;
            if (c.valid) cuts.push_back(c);
        }
        // A front that stands out nowhere (rising less than 0.25 % of the height from the waist
        // to the armpits: a shirt hanging straight over the chest) marks no bust line: then
        // the chest is the fullest of those sections, as a chest girth is taken under the arms.
        Real lowest_front = std::numeric_limits<Real>::infinity();
        for (const Cut& c : cuts) lowest_front = std::min(lowest_front, front(c));
        chest_flat = chest.valid && front(chest) - lowest_front < Real(0.0025) * h;
        if (chest_flat)
            for (const Cut& c : cuts)
                if (c.girth > chest.girth) chest = c;
    }
    out.waist = make_section(waist);
    out.hips = make_section(hips.valid ? hips : waist);
    out.chest = make_section(chest.valid ? chest : waist);
    const Vec3 meet(waist.center.x(), arms_skin, waist.center.z());
    out.arms_meet_trunk = body_point(rig, spine_bone_at(rig, out.spine, arms_skin), meet);

    const std::string pelvis_name = "'" + skeleton.bone_names[static_cast<std::size_t>(pelvis)] + "'";
    const std::string chest_name = "'" + skeleton.bone_names[static_cast<std::size_t>(out.chest_bone)] + "'";
    out.how_found = {
        {"pelvis", pelvis_name + (out.found_by == "bone names" ? ": its name, and two legs and a spine hang from it"
                                                               : ": topology, the highest bone with two legs and a spine hanging from it")},
        {"crotch", crotch_parted   ? "where the legs part: the lowest skin on the midplane between the thighs, above the knees"
                   : crotch_on_skin ? "the lowest skin of the pelvis bone at the midplane (the legs do not part above the knees)"
                                    : "5 % of the height under the pelvis joint (the legs do not part, no pelvis skin at the midplane)"},
        {"hips", hips.valid ? "the fullest section of the trunk's and thighs' skin between crotch and waist; the highest within 2 % of its girth"
                            : "the waist's (no section below it)"},
        {"waist", "the narrowest trunk section 30-80 % of the way from the crotch to where the arms' skin weights meet the trunk"},
        {"chest", !chest.valid ? "the waist's (no section above it)"
                  : std::string(armpits_on_skin == 2 ? "the section of the trunk (and the arms' first bones between the armpits) "
                                                     : "the trunk section ") +
                        (chest_flat ? "fullest between waist and armpits (the front is flat to 0.25 % of the height: no bust line)"
                                    : "reaching farthest forward between waist and armpits")},
        {"under the arms", armpits_by_shape ? "where the skin's section across the body parts into trunk and arm, scanning down from the shoulders; the higher side"
                           : armpits_on_skin == 2 ? "the lowest arm skin on a triangle shared with the trunk; the higher side"
                           : armpits_on_skin == 1 ? "one side's lowest arm skin shared with the trunk; the other 6 % of the height under its shoulder joint"
                                                  : "6 % of the height under the shoulder joints (arms and trunk are separate pieces)"},
        {"shoulders", (armpits_by_shape ? "the upper arms' heads: the first joint above each armpit and out to the trunk's side, of the two chains reaching farthest sideways from spine bone "
                                         : "the joints of the two chains reaching farthest sideways from spine bone ") + chest_name},
    };
    return out;
}

Vec3 landmark_world(const BodyPoint& point, const Skeleton& pose, const Transform& transform) {
    const Affine3 to_world = transform.matrix();
    if (point.bone < 0 || static_cast<std::size_t>(point.bone) >= pose.global.size()) return to_world * point.rest_m;
    return to_world * (rigid_part(pose.global[static_cast<std::size_t>(point.bone)]) * point.local_m);
}

}  // namespace drape
