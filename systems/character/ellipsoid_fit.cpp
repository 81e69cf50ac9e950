// Ellipsoid fitting and coverage (method §2). See ellipsoid_fit.hpp.
#include "drape/systems/character/ellipsoid_fit.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <map>
#include <cmath>
#include <numbers>
#include <string>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "drape/systems/character/ellipsoid_solver.hpp"
#include "drape/systems/character/pose.hpp"
#include "drape/systems/character/skin_surface.hpp"

namespace drape {

const char* body_region_name(BodyRegion region) noexcept {
    switch (region) {
        case BodyRegion::other: return "other";
        case BodyRegion::head: return "head";
        case BodyRegion::neck: return "neck";
        case BodyRegion::torso: return "torso";
        case BodyRegion::pelvis: return "pelvis";
        case BodyRegion::upper_arm: return "upper_arm";
        case BodyRegion::lower_arm: return "lower_arm";
        case BodyRegion::hand: return "hand";
        case BodyRegion::upper_leg: return "upper_leg";
        case BodyRegion::lower_leg: return "lower_leg";
        case BodyRegion::foot: return "foot";
    }
    return "other";
}

namespace {

std::string lower(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return std::tolower(c); });
    if (const auto colon = out.rfind(':'); colon != std::string::npos) out.erase(0, colon + 1);  // "mixamorig:Hips"
    return out;
}

bool has_any(const std::string& s, std::initializer_list<std::string_view> words) {
    for (std::string_view w : words)
        if (s.find(w) != std::string::npos) return true;
    return false;
}

std::optional<BodyRegion> region_from_string(std::string_view s) {
    for (int r = 0; r <= static_cast<int>(BodyRegion::foot); ++r)
        if (s == body_region_name(static_cast<BodyRegion>(r))) return static_cast<BodyRegion>(r);
    return std::nullopt;
}

// Surface points per ellipsoid for the bulge measure.
constexpr int bulge_samples_per_ellipsoid = 512;

// Points on the unit sphere, evenly spread (Fibonacci lattice).
Matrix3X sphere_samples(int n) {
    Matrix3X out(3, n);
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
        const double y = 1.0 - 2.0 * (i + 0.5) / n;
        const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
        out.col(i) = Vec3(static_cast<Real>(r * std::cos(golden * i)), static_cast<Real>(y),
                          static_cast<Real>(r * std::sin(golden * i)));
    }
    return out;
}

// The ellipsoid that bounds a cluster, in the bone frame `frame` (rigid, model space at
// bind): principal axes, centred on the box they span, scaled uniformly until 97 % of the
// points are inside. Bounded legs keep it (LegFit::bounding).
EllipsoidShape bounding_ellipsoid(const MeshAsset& mesh, const Affine3& frame, const std::vector<Eigen::Index>& c, double min_radius_m) {
    constexpr double cluster_coverage = 0.97;
    const Affine3 to_bone = frame.inverse();
    Matrix3X q(3, static_cast<Eigen::Index>(c.size()));
    for (std::size_t i = 0; i < c.size(); ++i) q.col(static_cast<Eigen::Index>(i)) = to_bone * mesh.bind_positions.col(c[i]);
    const Vec3 mean = q.rowwise().mean();
    Mat3 covariance = Mat3::Zero();
    for (Eigen::Index i = 0; i < q.cols(); ++i) {
        const Vec3 d = q.col(i) - mean;
        covariance.noalias() += d * d.transpose();
    }
    covariance /= Real(c.size());
    Eigen::SelfAdjointEigenSolver<Mat3> eig(covariance);
    Mat3 axes = eig.eigenvectors();
    if (!axes.allFinite()) axes.setIdentity();
    if (axes.determinant() < 0) axes.col(0) *= -1;
    const Matrix3X y = axes.transpose().lazyProduct(q);  // cluster in the principal frame
    const Vec3 lo = y.rowwise().minCoeff(), hi = y.rowwise().maxCoeff();
    const Vec3 centre_y = (lo + hi) / 2;
    const Vec3 half = ((hi - lo) / 2).cwiseMax(static_cast<Real>(min_radius_m));
    std::vector<Real> d(c.size());
    for (std::size_t i = 0; i < c.size(); ++i) d[i] = ((y.col(static_cast<Eigen::Index>(i)) - centre_y).cwiseQuotient(half)).norm();
    const auto k = std::min(d.size() - 1, static_cast<std::size_t>(std::ceil(cluster_coverage * double(d.size()))) - 1);
    std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(k), d.end());
    const Real s = std::max(d[k], Real(1e-3));
    EllipsoidShape shape;
    shape.center = axes * centre_y;
    shape.rotation = Quat(axes).normalized();
    shape.radii_m = (half * s).cwiseMax(static_cast<Real>(min_radius_m));
    return shape;
}

// Volume of the ellipsoid inscribed in a cluster's box along its principal axes, in the
// bind pose: what merging two clusters adds when the budget forces it.
double cluster_volume(const MeshAsset& mesh, const std::vector<Eigen::Index>& c) {
    if (c.size() < 4) return 0;
    std::vector<Eigen::Vector3d> points;
    for (Eigen::Index j : c) points.push_back(mesh.bind_positions.col(j).cast<double>());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : points) mean += p;
    mean /= double(points.size());
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const auto& p : points) covariance += (p - mean) * (p - mean).transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(covariance);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (const auto& p : points) {
        const Eigen::Vector3d y = eig.eigenvectors().transpose() * (p - mean);
        lo = lo.cwiseMin(y);
        hi = hi.cwiseMax(y);
    }
    return std::numbers::pi / 6 * (hi - lo).prod();
}

// "LeftArm" <-> "RightArm", "UpperArm.L" <-> "UpperArm.R", "thigh_l" <-> "thigh_r",
// "FootL" <-> "FootR"; empty when the name has no side.
std::string mirror_name(const std::string& name) {
    static const std::pair<std::string_view, std::string_view> swaps[] = {
        {"Left", "Right"}, {"left", "right"}, {".L", ".R"}, {".l", ".r"}, {"_L", "_R"}, {"_l", "_r"}};
    for (auto [a, b] : swaps)
        for (int flip = 0; flip < 2; ++flip) {
            const std::string_view from = flip ? b : a, to = flip ? a : b;
            if (const auto at = name.find(from); at != std::string::npos)
                return name.substr(0, at) + std::string(to) + name.substr(at + from.size());
        }
    if (!name.empty() && (name.back() == 'L' || name.back() == 'R'))
        return name.substr(0, name.size() - 1) + (name.back() == 'L' ? 'R' : 'L');
    return {};
}

// Per bone, the largest angle its local rotation turns away from the rest pose in any clip.
std::vector<double> joint_motion(const SkeletonAsset& skeleton, std::span<const std::shared_ptr<const AnimationClip>> clips) {
    std::vector<double> out(skeleton.size(), 0);
    for (const auto& clip : clips) {
        if (!clip) continue;
        for (const BoneChannel& ch : clip->channels) {
            if (ch.bone < 0 || static_cast<std::size_t>(ch.bone) >= skeleton.size()) continue;
            const Quat rest = skeleton.rest_rotation.empty() ? Quat::Identity() : skeleton.rest_rotation[static_cast<std::size_t>(ch.bone)];
            for (const Quat& q : ch.rotations)
                out[static_cast<std::size_t>(ch.bone)] = std::max(out[static_cast<std::size_t>(ch.bone)], double(rest.angularDistance(q)));
        }
    }
    return out;
}


// Connected pieces of a mesh: vertices joined by faces or by sharing a position (files
// split vertices along seams), as one label per vertex.
std::vector<int> mesh_islands(const MeshAsset& mesh, Real height_m) {
    const auto n = static_cast<int>(mesh.vertex_count());
    std::vector<int> parent(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) parent[static_cast<std::size_t>(i)] = i;
    auto root = [&](int x) {
        while (parent[static_cast<std::size_t>(x)] != x) x = parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
        return x;
    };
    auto join = [&](int a, int b) {
        a = root(a);
        b = root(b);
        if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
    };
    const double weld = 1e-5 * std::max(Real(1e-3), height_m);
    std::map<std::array<long long, 3>, int> at;
    for (int i = 0; i < n; ++i) {
        const Vec3 p = mesh.bind_positions.col(i);
        const std::array<long long, 3> key{std::llround(p.x() / weld), std::llround(p.y() / weld), std::llround(p.z() / weld)};
        const auto [it, fresh] = at.emplace(key, i);
        if (!fresh) join(i, it->second);
    }
    for (std::size_t f = 0; f + 2 < mesh.indices.size(); f += 3) {
        const auto a = static_cast<int>(mesh.indices[f]), b = static_cast<int>(mesh.indices[f + 1]), c = static_cast<int>(mesh.indices[f + 2]);
        if (a >= n || b >= n || c >= n) continue;
        join(a, b);
        join(b, c);
    }
    std::vector<int> out(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = root(i);
    return out;
}

// A rigid mesh is an object bound to a bone (a robot's plate, a ball joint): when one
// bone carries several such objects of some size, each is a part of its own, so that
// each gets its own ellipsoid to start from. Small objects (rivets) join the nearest
// large one. Skinned vertices stay in their bone's part. Parts beyond `budget` are not
// made (0: no limit).
void split_rigid_objects(const MeshAsset& mesh, std::span<const MeshInfo> meshes, Real height_m, int budget,
                         std::vector<int>& part_of_vertex, std::vector<int>& bone_of_part) {
    std::vector<char> rigid(mesh.vertex_count(), 0);
    bool any = false;
    for (const MeshInfo& m : meshes)
        if (m.rigid)
            for (std::uint32_t v = m.first_vertex; v < m.first_vertex + m.vertex_count && v < rigid.size(); ++v) rigid[v] = any = 1;
    if (!any) return;
    const std::vector<int> island = mesh_islands(mesh, height_m);
    struct Object {
        int island, part;
        std::vector<std::size_t> vertices;
        Eigen::AlignedBox3f box;
    };
    std::map<std::pair<int, int>, Object> objects;  // (part, island)
    for (std::size_t v = 0; v < rigid.size(); ++v) {
        if (!rigid[v] || part_of_vertex[v] < 0) continue;
        Object& o = objects[{part_of_vertex[v], island[v]}];
        o.island = island[v];
        o.part = part_of_vertex[v];
        o.vertices.push_back(v);
        o.box.extend(mesh.bind_positions.col(static_cast<Eigen::Index>(v)));
    }
    const double large = 0.05 * double(height_m);
    std::map<int, std::vector<const Object*>> large_of_part;
    for (const auto& [key, o] : objects)
        if (o.vertices.size() >= 16 && double(o.box.sizes().maxCoeff()) >= large) large_of_part[o.part].push_back(&o);
    int parts = static_cast<int>(bone_of_part.size());
    for (auto& [part, list] : large_of_part) {
        if (list.size() < 2) continue;
        // The largest object keeps the bone's part; the others get new ones while the budget lasts.
        std::stable_sort(list.begin(), list.end(), [](const Object* l, const Object* r) { return l->vertices.size() > r->vertices.size(); });
        std::vector<int> label(list.size(), part);
        for (std::size_t i = 1; i < list.size(); ++i) {
            if (budget > 0 && parts >= budget) break;
            label[i] = parts++;
            bone_of_part.push_back(bone_of_part[static_cast<std::size_t>(part)]);
        }
        // Every rigid vertex of the part goes with the nearest large object.
        for (const auto& [key, o] : objects) {
            if (o.part != part) continue;
            std::size_t nearest = 0;
            float best = std::numeric_limits<float>::max();
            for (std::size_t i = 0; i < list.size(); ++i) {
                const float d = list[i] == &o ? -1.f : list[i]->box.exteriorDistance(o.box.center());
                if (d < best) { best = d; nearest = i; }
            }
            for (std::size_t v : o.vertices) part_of_vertex[v] = label[nearest];
        }
    }
}

}  // namespace

Result<void> validate(const FitOptions& o) {
    if (!(o.min_cluster_fraction >= 0 && o.min_cluster_fraction < 1)) return fail("fit.min_cluster_fraction: must be in [0, 1)");
    if (!(o.min_cluster_size >= 0 && o.min_cluster_size < 1)) return fail("fit.min_cluster_size: must be in [0, 1)");
    if (!(o.tolerance_m > 0 && o.tolerance_m <= 1)) return fail("fit.tolerance_m: must be in (0, 1] m");
    if (!(o.bulge_limit_m > 0 && o.bulge_limit_m <= 1)) return fail("fit.bulge_limit_m: must be in (0, 1] m");
    if (!(o.sample_spacing > 0 && o.sample_spacing <= 0.5)) return fail("fit.sample_spacing: must be in (0, 0.5]");
    if (!(o.min_radius_m > 0 && std::isfinite(o.min_radius_m))) return fail("fit.min_radius_m: must be > 0");
    if (o.max_ellipsoids < 0) return fail("fit.max_ellipsoids: must be >= 0 (0: no limit)");
    if (!(o.leg_reach_m <= 1)) return fail("fit.leg_reach_m: must be <= 1 m (< 0: no limit)");
    if (!(o.arm_reach_m <= 1)) return fail("fit.arm_reach_m: must be <= 1 m (< 0: no limit)");
    if (!(o.target_coverage > 0 && o.target_coverage <= 1)) return fail("fit.target_coverage: must be in (0, 1]");
    if (!(o.knee_radius_share >= 0 && o.knee_radius_share <= 4)) return fail("fit.knee_radius_share: must be in [0, 4] (0: no knee spheres)");
    if (o.tight_extra_ellipsoids < 0) return fail("fit.tight_extra_ellipsoids: must be >= 0");
    if (!(o.thicken_thin_trunk_m >= 0 && o.thicken_thin_trunk_m <= 0.1)) return fail("fit.thicken_thin_trunk_m: must be in [0, 0.1] m (0: none)");
    if (o.legs != LegFit::automatic && o.legs != LegFit::tight && o.legs != LegFit::bounding)
        return fail("fit.legs: must be automatic, tight or bounding");
    return {};
}

BodyRegion region_from_bone_name(std::string_view name) noexcept {
    const std::string s = lower(name);
    if (has_any(s, {"hips", "pelvis"})) return BodyRegion::pelvis;
    if (has_any(s, {"hand", "palm", "finger", "thumb", "index", "middle", "ring", "pinky", "wrist"})) return BodyRegion::hand;
    if (has_any(s, {"forearm", "lowerarm", "lower_arm", "lowarm", "elbow"})) return BodyRegion::lower_arm;
    if (has_any(s, {"upperarm", "upper_arm", "uparm", "arm"})) return BodyRegion::upper_arm;
    if (has_any(s, {"foot", "toe", "ankle"})) return BodyRegion::foot;
    if (has_any(s, {"upleg", "upperleg", "upper_leg", "thigh"})) return BodyRegion::upper_leg;
    if (has_any(s, {"lowerleg", "lower_leg", "shin", "calf", "knee", "leg"})) return BodyRegion::lower_leg;
    if (has_any(s, {"neck"})) return BodyRegion::neck;
    if (has_any(s, {"head"})) return BodyRegion::head;
    if (has_any(s, {"spine", "chest", "torso", "abdomen", "belly", "waist", "shoulder", "clavicle"})) return BodyRegion::torso;
    return BodyRegion::other;
}

int find_hip_bone(const SkeletonAsset& skeleton) {
    for (std::size_t i = 0; i < skeleton.size(); ++i)
        if (region_from_bone_name(skeleton.bone_names[i]) == BodyRegion::pelvis) return static_cast<int>(i);
    // The deepest common ancestor of the upper legs.
    std::vector<int> legs;
    for (std::size_t i = 0; i < skeleton.size(); ++i)
        if (region_from_bone_name(skeleton.bone_names[i]) == BodyRegion::upper_leg) legs.push_back(static_cast<int>(i));
    if (legs.size() < 2) return -1;
    auto ancestors = [&](int b) {
        std::vector<int> out;
        for (int p = skeleton.parents[static_cast<std::size_t>(b)]; p >= 0; p = skeleton.parents[static_cast<std::size_t>(p)])
            out.push_back(p);
        return out;
    };
    const std::vector<int> a = ancestors(legs[0]);
    const std::vector<int> other = ancestors(legs[1]);
    for (int candidate : a)
        if (std::find(other.begin(), other.end(), candidate) != other.end()) return candidate;
    return -1;
}

std::vector<int> dominant_bones(const MeshAsset& mesh) {
    std::vector<int> out(mesh.vertex_count(), 0);
    for (Eigen::Index j = 0; j < mesh.bone_weights.cols(); ++j) {
        Eigen::Index k = 0;
        mesh.bone_weights.col(j).maxCoeff(&k);
        out[static_cast<std::size_t>(j)] = mesh.bone_indices(k, j);
    }
    return out;
}

namespace {

// fit_ellipsoids with the legs fitted tight (`tight_legs`) or bounded.
std::vector<EllipsoidShape> fit_with(const SkeletonAsset& skeleton, const MeshAsset& mesh, Real height_m,
                                     const FitOptions& options, std::span<const std::shared_ptr<const AnimationClip>> clips,
                                     std::span<const MeshInfo> meshes, bool tight_legs) {
    const std::size_t bones = skeleton.size();
    const std::size_t n = mesh.vertex_count();
    std::vector<std::vector<Eigen::Index>> clusters(bones);
    const std::vector<int> dominant = dominant_bones(mesh);
    for (std::size_t j = 0; j < n; ++j) clusters[static_cast<std::size_t>(dominant[j])].push_back(static_cast<Eigen::Index>(j));

    // Bone frames at bind (rigid: metres), model space.
    std::vector<Affine3> frame(bones);
    for (std::size_t b = 0; b < bones; ++b) frame[b] = rigid_part(skeleton.inverse_bind[b].inverse());

    // Small clusters hand their vertices to the parent; children are visited first.
    const int hip = find_hip_bone(skeleton);
    std::vector<bool> holds_hip(bones, false);  // the cluster took in the hip bone's vertices
    if (hip >= 0) holds_hip[static_cast<std::size_t>(hip)] = true;
    const auto min_count = static_cast<std::size_t>(std::ceil(options.min_cluster_fraction * double(n)));
    const Real min_size = static_cast<Real>(options.min_cluster_size) * height_m;
    for (std::size_t b = bones; b-- > 0;) {
        auto& c = clusters[b];
        if (c.empty()) continue;
        Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::max()), hi = -lo;
        for (Eigen::Index j : c) {
            lo = lo.cwiseMin(mesh.bind_positions.col(j));
            hi = hi.cwiseMax(mesh.bind_positions.col(j));
        }
        const bool small = c.size() < std::max<std::size_t>(min_count, 4) || (hi - lo).norm() < min_size;
        if (!small) continue;
        const int parent = skeleton.parents[b];
        if (parent >= 0) {
            auto& target = clusters[static_cast<std::size_t>(parent)];
            target.insert(target.end(), c.begin(), c.end());
            if (holds_hip[b]) holds_hip[static_cast<std::size_t>(parent)] = true;
        }
        c.clear();
    }

    // A hand or a foot gets one ellipsoid: its clusters join the topmost bone of the same
    // region above them, and sibling clusters of that region (separate palm bones) join
    // the first of them.
    auto region_of = [&](std::size_t b) { return region_from_bone_name(skeleton.bone_names[b]); };
    auto extremity = [](BodyRegion r) { return r == BodyRegion::hand || r == BodyRegion::foot; };
    auto limb = [](BodyRegion r) { return is_arm(r) || is_leg(r); };
    auto move = [&](std::size_t from, std::size_t to) {
        auto& target = clusters[to];
        target.insert(target.end(), clusters[from].begin(), clusters[from].end());
        clusters[from].clear();
        if (holds_hip[from]) holds_hip[to] = true;
    };
    for (std::size_t b = bones; b-- > 0;) {
        if (clusters[b].empty() || !extremity(region_of(b))) continue;
        std::size_t top = b;
        while (skeleton.parents[top] >= 0 && region_of(static_cast<std::size_t>(skeleton.parents[top])) == region_of(b))
            top = static_cast<std::size_t>(skeleton.parents[top]);
        if (top != b) move(b, top);
    }
    // Siblings join only when their joints nearly coincide (palm bones fanning out of one
    // wrist), never a left and a right foot that hang from the same root.
    const Real joint_near = Real(0.08) * height_m;
    for (std::size_t b = 0; b < bones; ++b) {
        if (clusters[b].empty() || !extremity(region_of(b))) continue;
        for (std::size_t s = b + 1; s < bones; ++s)
            if (!clusters[s].empty() && skeleton.parents[s] == skeleton.parents[b] && region_of(s) == region_of(b) &&
                (frame[s].translation() - frame[b].translation()).norm() < joint_near)
                move(s, b);
    }

    // Too many clusters for the budget: merge, one at a time, the child cluster whose joint
    // moves least in the clips (a stiff back, a clavicle before an elbow), ties broken by
    // the ellipsoid volume the union adds; a left/right partner merges along with it so
    // the body stays symmetric.
    auto nearest_ancestor = [&](std::size_t b) -> int {
        for (int p = skeleton.parents[b]; p >= 0; p = skeleton.parents[static_cast<std::size_t>(p)])
            if (clusters[static_cast<std::size_t>(p)].size() >= 4) return p;
        return -1;
    };
    auto fitted = [&](std::size_t b) { return clusters[b].size() >= 4; };
    const std::vector<double> motion = joint_motion(skeleton, clips);
    std::size_t active = 0;
    for (std::size_t b = 0; b < bones; ++b) active += fitted(b) ? 1 : 0;
    const double unit_volume = std::max(1e-9, double(height_m) * height_m * height_m);
    while (options.max_ellipsoids > 0 && active > static_cast<std::size_t>(options.max_ellipsoids)) {
        double best_cost = std::numeric_limits<double>::max();
        std::size_t best_child = bones, best_parent = bones;
        for (std::size_t b = 0; b < bones; ++b) {
            if (!fitted(b)) continue;
            const int a = nearest_ancestor(b);
            if (a < 0) continue;
            const auto pa = static_cast<std::size_t>(a);
            std::vector<Eigen::Index> both = clusters[pa];
            both.insert(both.end(), clusters[b].begin(), clusters[b].end());
            const double added = cluster_volume(mesh, both) - cluster_volume(mesh, clusters[pa]) - cluster_volume(mesh, clusters[b]);
            // Motion between b and its ancestor: every joint on the way moves the cluster.
            double moves = 0;
            for (std::size_t j = b; j != pa; j = static_cast<std::size_t>(skeleton.parents[j])) moves = std::max(moves, motion[j]);
            const double cost = moves + 10 * std::max(0.0, added) / unit_volume;
            if (cost < best_cost) { best_cost = cost; best_child = b; best_parent = pa; }
        }
        if (best_child == bones) break;
        const int partner = skeleton.find(mirror_name(skeleton.bone_names[best_child]));
        move(best_child, best_parent);
        --active;
        if (partner >= 0 && static_cast<std::size_t>(partner) != best_child && fitted(static_cast<std::size_t>(partner))) {
            const int a = nearest_ancestor(static_cast<std::size_t>(partner));
            if (a >= 0) {
                move(static_cast<std::size_t>(partner), static_cast<std::size_t>(a));
                --active;
            }
        }
    }

    // Parts: the surviving clusters. Their skin at the rest pose is sampled and fitted.
    std::vector<int> part_of_bone(bones, -1), bone_of_part;
    for (std::size_t b = 0; b < bones; ++b)
        if (fitted(b)) {
            part_of_bone[b] = static_cast<int>(bone_of_part.size());
            bone_of_part.push_back(static_cast<int>(b));
        }
    std::vector<int> part_of_vertex(n, -1);
    for (std::size_t b = 0; b < bones; ++b)
        if (fitted(b))
            for (Eigen::Index j : clusters[b]) part_of_vertex[static_cast<std::size_t>(j)] = part_of_bone[b];
    const std::size_t bone_parts = bone_of_part.size();
    split_rigid_objects(mesh, meshes, height_m, static_cast<int>(bone_parts) + 4 <= options.max_ellipsoids || options.max_ellipsoids == 0
                                                    ? options.max_ellipsoids - 4 : 0,
                        part_of_vertex, bone_of_part);
    std::vector<fitting::PartInfo> part_info(bone_of_part.size());
    for (std::size_t p = 0; p < bone_parts; ++p) {
        const int partner = skeleton.find(mirror_name(skeleton.bone_names[static_cast<std::size_t>(bone_of_part[p])]));
        if (partner >= 0 && partner != bone_of_part[p]) part_info[p].mirror = part_of_bone[static_cast<std::size_t>(partner)];
        const BodyRegion region = region_of(static_cast<std::size_t>(bone_of_part[p]));
        part_info[p].may_split = !limb(region);
        // A limb bone's piece may not reach past its own skin along the limb: an upper or
        // lower arm when the arm reach is set (an option), a leg where it is hugged (only
        // hugged legs keep their fitted ellipsoid; the reach term on legs that are replaced
        // by their bounding ellipsoids below would still move their neighbours).
        const bool arm = region == BodyRegion::upper_arm || region == BodyRegion::lower_arm;
        const bool leg = region == BodyRegion::upper_leg || region == BodyRegion::lower_leg;
        if (arm && options.arm_reach_m >= 0) {
            part_info[p].limited_reach = true;
            part_info[p].reach_m = options.arm_reach_m;
        } else if (leg && tight_legs && options.leg_reach_m >= 0) {
            part_info[p].limited_reach = true;
            part_info[p].reach_m = options.leg_reach_m;
        }
    }

    std::vector<Affine3> global, skinning;
    compose_pose(skeleton, skeleton.rest_local, global);
    skinning_matrices(skeleton, global, skinning);
    Matrix3X positions, normals;
    skin_mesh(mesh, skinning, Affine3::Identity(), positions, normals);
    const std::vector<SkinSample> samples = sample_skin(positions, normals, mesh.indices, options.sample_spacing * double(height_m));
    std::vector<int> part_of(samples.size(), -1);
    for (std::size_t s = 0; s < samples.size(); ++s) part_of[s] = part_of_vertex[samples[s].vertex];

    fitting::SolverSettings settings;
    settings.coverage_tolerance_m = options.tolerance_m;
    settings.cover_margin_m = 0.5 * options.tolerance_m;
    settings.bulge_limit_m = options.bulge_limit_m;
    settings.min_radius_m = options.min_radius_m;
    settings.max_pieces = options.max_ellipsoids > 0 ? options.max_ellipsoids + (tight_legs ? options.tight_extra_ellipsoids : 0) : 1 << 20;
    // Tight legs: a sphere at each knee (below), on top of the budget.
    std::vector<int> knees;
    if (tight_legs && options.knee_radius_share > 0)
        for (const int b : bone_of_part)
            if (region_of(static_cast<std::size_t>(b)) == BodyRegion::lower_leg && std::find(knees.begin(), knees.end(), b) == knees.end())
                knees.push_back(b);
    const SkinSurface skin(positions, normals, mesh.indices);
    std::vector<fitting::Piece> pieces = fitting::fit_pieces(skin, samples, part_of, part_info, settings);
    // Grouped by bone, in the order of the skeleton; a bone's pieces in the order they came.
    std::stable_sort(pieces.begin(), pieces.end(), [](const auto& l, const auto& r) { return l.part < r.part; });

    std::vector<EllipsoidShape> shapes;
    for (const fitting::Piece& piece : pieces) {
        const auto b = static_cast<std::size_t>(bone_of_part[static_cast<std::size_t>(piece.part)]);
        // Bone space: the rigid part of the bone's rest transform (scale-free, metres).
        const Eigen::Isometry3d to_bone = Eigen::Isometry3d(rigid_part(global[b]).matrix().cast<double>()).inverse();
        EllipsoidShape shape;
        shape.bone = static_cast<int>(b);
        shape.center = (to_bone * piece.shape.center).cast<Real>();
        shape.rotation = Quat(Eigen::Quaterniond(to_bone.linear() * piece.shape.axes).normalized().cast<Real>());
        shape.radii_m = piece.shape.radii.cast<Real>().cwiseMax(static_cast<Real>(options.min_radius_m));
        shape.region = holds_hip[b] ? BodyRegion::pelvis : region_from_bone_name(skeleton.bone_names[b]);
        // A bounded leg keeps the ellipsoid that bounds its bone's vertices: see LegFit.
        if (!tight_legs && (shape.region == BodyRegion::upper_leg || shape.region == BodyRegion::lower_leg) &&
            static_cast<std::size_t>(piece.part) < bone_parts) {
            std::vector<Eigen::Index> own;
            for (std::size_t j = 0; j < n; ++j)
                if (part_of_vertex[j] == piece.part) own.push_back(static_cast<Eigen::Index>(j));
            const BodyRegion region = shape.region;
            shape = bounding_ellipsoid(mesh, rigid_part(skeleton.inverse_bind[b].inverse()), own, options.min_radius_m);
            shape.bone = static_cast<int>(b);
            shape.region = region;
        }
        shapes.push_back(shape);
    }
    // The knee spheres: capsule chains put a sphere at every joint; the thigh's and the
    // shin's tight ellipsoids leave a crease behind the knee that closes on a hem as the knee
    // bends. Centred on the shin bone's joint, knee_radius_share x the distance from the
    // joint to the nearest skin of the thigh and the shin.
    for (const int b : knees) {
        const int thigh = skeleton.parents[static_cast<std::size_t>(b)];
        const Vec3 joint = global[static_cast<std::size_t>(b)].translation();
        Real nearest = std::numeric_limits<Real>::max();
        for (std::size_t j = 0; j < n; ++j)
            if (dominant[j] == b || dominant[j] == thigh)
                nearest = std::min(nearest, (positions.col(static_cast<Eigen::Index>(j)) - joint).norm());
        if (nearest == std::numeric_limits<Real>::max()) continue;
        EllipsoidShape knee;
        knee.bone = b;  // bone space: the joint is the origin
        knee.radii_m = Vec3::Constant(std::max(static_cast<Real>(options.knee_radius_share) * nearest, static_cast<Real>(options.min_radius_m)));
        knee.region = BodyRegion::lower_leg;
        shapes.push_back(knee);
    }
    // No cluster holds the hip bone's vertices (a rig whose pelvis mesh hangs from a
    // sibling bone): the trunk ellipsoids nearest the hip joint stand for the pelvis.
    const bool has_pelvis = std::any_of(shapes.begin(), shapes.end(), [](auto& s) { return s.region == BodyRegion::pelvis; });
    if (!has_pelvis && hip >= 0) {
        const Vec3 hip_at = global[static_cast<std::size_t>(hip)].translation();
        int nearest = -1;
        Real best = std::numeric_limits<Real>::max();
        for (const EllipsoidShape& s : shapes) {
            if (s.region != BodyRegion::other && s.region != BodyRegion::torso) continue;
            const Real d = (rigid_part(global[static_cast<std::size_t>(s.bone)]) * s.center - hip_at).norm();
            if (d < best) { best = d; nearest = s.bone; }
        }
        for (EllipsoidShape& s : shapes)
            if (s.bone == nearest) s.region = BodyRegion::pelvis;
    }
    return shapes;
}

}  // namespace

const char* leg_fit_name(LegFit legs) noexcept {
    switch (legs) {
        case LegFit::automatic: return "automatic";
        case LegFit::tight: return "tight";
        case LegFit::bounding: return "bounding";
    }
    return "unknown";
}

bool covers_skin(const CoverageReport& report, const FitOptions& options) noexcept {
    return report.coverage >= options.target_coverage;
}

bool meets_fit_targets(const CoverageReport& report, const FitOptions& options) noexcept {
    return covers_skin(report, options) && report.p95_bulge_m <= options.bulge_limit_m;
}

void thicken_thin_trunk_pieces(std::vector<EllipsoidShape>& shapes, std::span<const Affine3> global, const Matrix3X& positions,
                               const Matrix3X& normals, const FitOptions& options) {
    const Real thin = static_cast<Real>(options.thicken_thin_trunk_m);
    if (!(thin > 0)) return;
    const Real tolerance = static_cast<Real>(options.tolerance_m);
    constexpr Real reach_m = Real(0.12), step_m = Real(0.002);  // how far behind a shell the thick pieces are looked for
    // A shell covers a patch of skin: its middle radius is at least this times its thin one.
    // Balls and rods (on a loose shirt's folds) are left: grown inward, they tore
    // Male_LongSleeve's running skirts (docs/cloth.md, "Collision").
    constexpr Real shell_ratio = 2;
    const auto trunk = [](const EllipsoidShape& e) { return e.region == BodyRegion::torso || e.region == BodyRegion::pelvis; };
    const auto posed = [&](const EllipsoidShape& e) { return e.bone >= 0 && static_cast<std::size_t>(e.bone) < global.size(); };
    // Unit-sphere maps of the thick trunk pieces, as they are before any is changed.
    std::vector<Affine3> thick;
    for (const EllipsoidShape& e : shapes)
        if (trunk(e) && posed(e) && e.radii_m.minCoeff() > thin)
            thick.push_back(ellipsoid_transform(e, global[static_cast<std::size_t>(e.bone)]).inverse());
    for (EllipsoidShape& s : shapes) {
        if (!trunk(s) || !posed(s)) continue;
        int axis = 0;
        const Real r0 = s.radii_m.minCoeff(&axis);
        if (r0 > thin) continue;
        Vec3 sorted = s.radii_m;
        std::sort(sorted.data(), sorted.data() + 3);
        if (sorted[1] < shell_ratio * r0) continue;  // a ball or a rod on a fold, not a shell
        const Affine3 bone = rigid_part(global[static_cast<std::size_t>(s.bone)]);
        const Affine3 placed = ellipsoid_transform(s, global[static_cast<std::size_t>(s.bone)]);
        const Vec3 c = placed.translation();
        const Vec3 a = (bone.linear() * s.rotation.toRotationMatrix()).col(axis);  // the thin axis, model space
        // The skin it covers faces outward: the sum of its normals, within the tolerance.
        Vec3 facing = Vec3::Zero();
        const Real near = s.radii_m.maxCoeff() + tolerance;
        for (Eigen::Index v = 0; v < positions.cols(); ++v)
            if ((positions.col(v) - c).squaredNorm() <= near * near && outside_distance(placed, positions.col(v)) <= tolerance)
                facing += normals.col(v).normalized();
        const Real along = facing.dot(a);
        if (!(std::abs(along) > 0)) continue;
        const Vec3 inward = along > 0 ? Vec3(-a) : a;
        Real depth = -1;  // from the centre, inward, to the first thick piece
        for (Real t = step_m; t <= reach_m && depth < 0; t += step_m)
            for (const Affine3& to_unit : thick)
                if ((to_unit * (c + t * inward)).squaredNorm() < 1) {
                    depth = t;
                    break;
                }
        const Real k = (depth + tolerance - r0) / 2;
        if (depth < 0 || k <= 0) continue;
        s.radii_m[axis] = r0 + k;
        s.center += bone.linear().transpose() * (k * inward);  // bone space
    }
}

std::vector<EllipsoidShape> fit_ellipsoids(const SkeletonAsset& skeleton, const MeshAsset& mesh, Real height_m,
                                           const FitOptions& options,
                                           std::span<const std::shared_ptr<const AnimationClip>> clips,
                                           std::span<const MeshInfo> meshes, LegFit* legs) {
    std::vector<Affine3> global, skinning;
    compose_pose(skeleton, skeleton.rest_local, global);
    skinning_matrices(skeleton, global, skinning);
    Matrix3X positions, normals;
    skin_mesh(mesh, skinning, Affine3::Identity(), positions, normals);
    const auto measure = [&](std::span<const EllipsoidShape> shapes) {
        return measure_coverage(shapes, global, positions, normals, mesh.indices, options.tolerance_m);
    };
    LegFit used = options.legs;
    std::vector<EllipsoidShape> shapes = fit_with(skeleton, mesh, height_m, options, clips, meshes, options.legs != LegFit::bounding);
    CoverageReport report = measure(shapes);
    if (options.legs == LegFit::automatic) {
        // The tight legs where the whole fit then covers the skin to the target at the rest
        // pose (covers_skin).
        used = LegFit::tight;
        if (!covers_skin(report, options)) {
            used = LegFit::bounding;
            shapes = fit_with(skeleton, mesh, height_m, options, clips, meshes, false);
            report = measure(shapes);
        }
    }
    if (legs) *legs = used;
    // Forearms and hands give by their bulge over the skin (EllipsoidCollider::give_m).
    if (report.bulge_per_ellipsoid_m.size() == shapes.size())  // one per shape: every fitted bone is in the skeleton
        for (std::size_t i = 0; i < shapes.size(); ++i)
            if (shapes[i].region == BodyRegion::lower_arm || shapes[i].region == BodyRegion::hand)
                shapes[i].give_m = static_cast<Real>(report.bulge_per_ellipsoid_m[i]);
    thicken_thin_trunk_pieces(shapes, global, positions, normals, options);
    return shapes;
}

Affine3 ellipsoid_transform(const EllipsoidShape& shape, const Affine3& bone_global) {
    Affine3 local = Affine3::Identity();
    local.translate(shape.center);
    local.rotate(shape.rotation);
    local.scale(shape.radii_m);
    return rigid_part(bone_global) * local;
}

Real outside_distance(const Affine3& e, const Vec3& point) {
    // Unit sphere -> space: the linear part's columns are the axes scaled by the radii.
    Eigen::Vector3d radii;
    Eigen::Matrix3d axes;
    for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d column = e.linear().col(k).cast<double>();
        radii[k] = column.norm();
        axes.col(k) = radii[k] > 0 ? Eigen::Vector3d(column / radii[k]) : Eigen::Vector3d::Unit(k);
    }
    const Eigen::Vector3d q = axes.transpose() * (point - e.translation()).cast<double>();
    return static_cast<Real>(fitting::outside_distance(radii.cwiseMax(1e-12), q));
}

CoverageReport measure_coverage(std::span<const EllipsoidShape> shapes, std::span<const Affine3> global,
                                const Matrix3X& positions, const Matrix3X& normals, std::span<const std::uint32_t> triangles,
                                double tolerance_m) {
    CoverageReport report;
    report.tolerance_m = tolerance_m;
    report.vertices = static_cast<std::size_t>(positions.cols());
    std::vector<Affine3> e, e_inverse;
    for (const EllipsoidShape& s : shapes) {
        if (s.bone < 0 || static_cast<std::size_t>(s.bone) >= global.size()) continue;
        e.push_back(ellipsoid_transform(s, global[static_cast<std::size_t>(s.bone)]));
        e_inverse.push_back(e.back().inverse(Eigen::Affine));
    }
    const Eigen::Index n = positions.cols();
    std::vector<Real> gap(static_cast<std::size_t>(n), std::numeric_limits<Real>::infinity());
    tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, n, 1024), [&](const tbb::blocked_range<Eigen::Index>& r) {
        for (Eigen::Index j = r.begin(); j < r.end(); ++j) {
            Real best = std::numeric_limits<Real>::infinity();
            const Vec3 p = positions.col(j);
            for (std::size_t k = 0; k < e.size() && best > 0; ++k) best = std::min(best, outside_distance(e[k], p));
            gap[static_cast<std::size_t>(j)] = best;
        }
    });
    for (Real g : gap) {
        if (g <= tolerance_m) ++report.covered;
        else report.max_gap_m = std::max(report.max_gap_m, double(g));
    }
    report.coverage = report.vertices ? double(report.covered) / double(report.vertices) : 0;

    // Bulge on the union's surface: samples of each ellipsoid that no other ellipsoid
    // holds, against the closest point of the skin's triangles.
    const SkinSurface skin(positions, normals, triangles);
    const Matrix3X unit = sphere_samples(bulge_samples_per_ellipsoid);
    struct Sample {
        double bulge_m;  // < 0: inside the skin
        double area_m2;
    };
    std::vector<std::vector<Sample>> per(e.size());
    tbb::parallel_for(std::size_t(0), e.size(), [&](std::size_t k) {
        const Vec3 radii(e[k].linear().col(0).norm(), e[k].linear().col(1).norm(), e[k].linear().col(2).norm());
        for (Eigen::Index s = 0; s < unit.cols(); ++s) {
            const Vec3 u = unit.col(s);
            const Vec3 x = e[k] * u;
            bool buried = false;
            for (std::size_t other = 0; other < e.size() && !buried; ++other)
                buried = other != k && (e_inverse[other] * x).squaredNorm() < Real(1 - 1e-6);
            if (buried) continue;
            // Area element of the unit sphere mapped onto the ellipsoid: r1 r2 r3 |u / r|.
            const double area = 4 * std::numbers::pi / double(unit.cols()) * double(radii.prod()) * double(u.cwiseQuotient(radii).norm());
            const SkinSurface::Closest c = skin.closest(x.cast<double>());
            if (c.triangle < 0) continue;
            per[k].push_back({c.outside ? c.distance_m : -c.distance_m, area});
        }
    });
    report.bulge_per_ellipsoid_m.assign(e.size(), 0);
    std::vector<Sample> out;
    double surface = 0;
    for (std::size_t k = 0; k < e.size(); ++k)
        for (const Sample& s : per[k]) {
            surface += s.area_m2;
            if (s.bulge_m <= 0) continue;
            report.bulge_per_ellipsoid_m[k] = std::max(report.bulge_per_ellipsoid_m[k], s.bulge_m);
            out.push_back(s);
        }
    report.surface_m2 = surface;
    if (!out.empty()) {
        std::sort(out.begin(), out.end(), [](const Sample& l, const Sample& r) { return l.bulge_m < r.bulge_m; });
        double area = 0, weighted = 0;
        for (const Sample& s : out) {
            area += s.area_m2;
            weighted += s.area_m2 * s.bulge_m;
        }
        report.outside_share = surface > 0 ? area / surface : 0;
        report.mean_bulge_m = weighted / area;
        double below = 0;
        report.p95_bulge_m = out.back().bulge_m;
        for (const Sample& s : out) {
            below += s.area_m2;
            if (below >= 0.95 * area) {
                report.p95_bulge_m = s.bulge_m;
                break;
            }
        }
        report.max_bulge_m = out.back().bulge_m;
    }
    return report;
}

Result<std::vector<EllipsoidShape>> ellipsoids_from_json(std::string_view json_text, const SkeletonAsset& skeleton,
                                                        std::string_view source) {
    const std::string at(source);
    nlohmann::json doc = nlohmann::json::parse(json_text, nullptr, false);
    if (doc.is_discarded()) return fail(at + ": colliders: not valid JSON");
    if (!doc.is_array()) return fail(at + ": colliders: must be an array");
    auto read_vec = [&](const nlohmann::json& item, const std::string& field, std::size_t count,
                        std::vector<double>& out) -> Result<void> {
        if (!item.contains(field)) return fail(at + ": " + field + ": missing");
        const auto& v = item.at(field);
        if (!v.is_array() || v.size() != count) return fail(at + ": " + field + ": must be an array of " + std::to_string(count) + " numbers");
        out.clear();
        for (const auto& x : v) {
            if (!x.is_number() || !std::isfinite(x.get<double>())) return fail(at + ": " + field + ": must hold finite numbers");
            out.push_back(x.get<double>());
        }
        return {};
    };
    std::vector<EllipsoidShape> shapes;
    for (std::size_t i = 0; i < doc.size(); ++i) {
        const auto& item = doc[i];
        const std::string field = "colliders[" + std::to_string(i) + "]";
        if (!item.is_object()) return fail(at + ": " + field + ": must be an object");
        EllipsoidShape s;
        if (!item.contains("bone") || !item["bone"].is_string()) return fail(at + ": " + field + ".bone: must be a bone name");
        const std::string bone = item["bone"].get<std::string>();
        s.bone = skeleton.find(bone);
        if (s.bone < 0) return fail(at + ": " + field + ".bone: no bone named '" + bone + "'");
        std::vector<double> v;
        if (auto ok = read_vec(item, "center", 3, v); !ok) return fail(at + ": " + field + "." + ok.error().message.substr(at.size() + 2));
        s.center = Vec3(static_cast<Real>(v[0]), static_cast<Real>(v[1]), static_cast<Real>(v[2]));
        if (auto ok = read_vec(item, "radii_m", 3, v); !ok) return fail(at + ": " + field + "." + ok.error().message.substr(at.size() + 2));
        if (v[0] <= 0 || v[1] <= 0 || v[2] <= 0) return fail(at + ": " + field + ".radii_m: must be > 0");
        s.radii_m = Vec3(static_cast<Real>(v[0]), static_cast<Real>(v[1]), static_cast<Real>(v[2]));
        if (item.contains("rotation")) {
            if (auto ok = read_vec(item, "rotation", 4, v); !ok) return fail(at + ": " + field + "." + ok.error().message.substr(at.size() + 2));
            Quat q(static_cast<Real>(v[3]), static_cast<Real>(v[0]), static_cast<Real>(v[1]), static_cast<Real>(v[2]));
            if (q.norm() < 1e-6f) return fail(at + ": " + field + ".rotation: must be a non-zero quaternion [x, y, z, w]");
            s.rotation = q.normalized();
        }
        s.region = region_from_bone_name(bone);
        if (item.contains("region")) {
            const auto r = item["region"].is_string() ? region_from_string(item["region"].get<std::string>()) : std::nullopt;
            if (!r) return fail(at + ": " + field + ".region: unknown region (head, neck, torso, pelvis, upper_arm, lower_arm, hand, upper_leg, lower_leg, foot, other)");
            s.region = *r;
        }
        if (item.contains("give_m")) {
            const auto& g = item["give_m"];
            if (!g.is_number() || !std::isfinite(g.get<double>()) || g.get<double>() < 0 || g.get<double>() > 0.5)
                return fail(at + ": " + field + ".give_m: must be a number in [0, 0.5] m");
            s.give_m = static_cast<Real>(g.get<double>());
        }
        shapes.push_back(s);
    }
    return shapes;
}

std::vector<EllipsoidShape> apply_overrides(std::span<const EllipsoidShape> fitted, std::span<const EllipsoidShape> overrides,
                                            bool replace_all) {
    std::vector<EllipsoidShape> out;
    if (!replace_all)
        for (const EllipsoidShape& f : fitted) {
            const bool overridden = std::any_of(overrides.begin(), overrides.end(), [&](const EllipsoidShape& o) { return o.bone == f.bone; });
            if (!overridden) out.push_back(f);
        }
    out.insert(out.end(), overrides.begin(), overrides.end());
    return out;
}

}  // namespace drape
