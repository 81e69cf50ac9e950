// Drape's default avatar (docs/avatar.md).
//
// Steps, in order:
//  1. Skeleton: 25 joints with the usual humanoid names, A-pose (arms 20 degrees off the
//     body so a dress and the arm colliders keep apart), Y up, +Z forward, metres.
//  2. Body: a signed distance field, the smooth union (polynomial smooth minimum) of tapered
//     capsules and ellipsoids, each owned by one bone (method §2: a skinned character).
//  3. Mesh: surface nets on a regular grid; each vertex is pulled onto the zero set by a few
//     Newton steps, its normal is the field's gradient.
//  4. Skin: a vertex's weight for a bone falls off with how much farther the bone's own
//     shapes are than the nearest shapes; at most 4 influences, normalised.
//  5. Clips: a procedural in-place walk (gait-cycle curves for hip, knee, ankle and toe
//     flexion, arm swing opposite the legs, elbow bend, pelvis rotation and list, torso
//     counter-rotation) and a breathing idle; the pelvis height is solved each frame so the
//     lowest point of the soles touches the floor, which gives the walk its vertical bob.
//  6. Export through assimp's glb2 writer (the one exporter whose skins and animations
//     re-import intact, see ../shared/assets/README.md).
//
// Determinism: plain double arithmetic in a fixed order, ordered containers only, no clocks;
// the exporter is fed one scene built the same way each time and writes to memory, so the
// output path never leaks into the bytes.
#include "drape/game/avatar_generator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <numbers>

#include <assimp/Exporter.hpp>
#include <assimp/material.h>
#include <assimp/scene.h>
#include <nlohmann/json.hpp>

namespace drape {
namespace {

using Eigen::Matrix3d;
using Eigen::Quaterniond;
using Eigen::Vector3d;

constexpr double reference_height_m = 1.75;  // The proportions below are for this height.
constexpr double pi = std::numbers::pi;
constexpr double arm_abduction_rad = 20.0 * pi / 180.0;  // A-pose: arms 20 degrees off the sides.

double radians(double degrees) { return degrees * pi / 180.0; }

// ---------------------------------------------------------------------------------------
// 1. Skeleton

enum Bone : int {
    Hips, Spine, Spine1, Spine2, Neck, Head, HeadTop_End,
    LeftShoulder, LeftArm, LeftForeArm, LeftHand,
    RightShoulder, RightArm, RightForeArm, RightHand,
    LeftUpLeg, LeftLeg, LeftFoot, LeftToeBase, LeftToe_End,
    RightUpLeg, RightLeg, RightFoot, RightToeBase, RightToe_End,
    BoneCount
};

// Unit direction of the left arm hanging in the A-pose (the right arm mirrors it in x).
Vector3d arm_direction(double side) { return {side * std::sin(arm_abduction_rad), -std::cos(arm_abduction_rad), 0.0}; }

// The left side is +x (the avatar faces +z); `side` is +1 for left, -1 for right.
std::vector<AvatarBone> make_skeleton(double s) {
    std::vector<AvatarBone> bones(BoneCount);
    auto set = [&](Bone bone, const char* name, int parent, Vector3d joint) {
        bones[bone] = AvatarBone{name, parent, joint * s};
    };
    set(Hips, "Hips", -1, {0.0, 0.96, 0.0});
    set(Spine, "Spine", Hips, {0.0, 1.04, -0.005});
    set(Spine1, "Spine1", Spine, {0.0, 1.15, -0.01});
    set(Spine2, "Spine2", Spine1, {0.0, 1.27, -0.01});
    set(Neck, "Neck", Spine2, {0.0, 1.455, -0.015});
    set(Head, "Head", Neck, {0.0, 1.56, 0.0});
    set(HeadTop_End, "HeadTop_End", Head, {0.0, 1.75, 0.0});
    for (double side : {1.0, -1.0}) {
        const bool left = side > 0;
        const Vector3d shoulder(side * 0.185, 1.415, -0.015);
        const Vector3d elbow = shoulder + 0.285 * arm_direction(side);
        const Vector3d wrist = elbow + 0.255 * arm_direction(side);
        set(left ? LeftShoulder : RightShoulder, left ? "LeftShoulder" : "RightShoulder", Spine2, {side * 0.035, 1.41, 0.0});
        set(left ? LeftArm : RightArm, left ? "LeftArm" : "RightArm", left ? LeftShoulder : RightShoulder, shoulder);
        set(left ? LeftForeArm : RightForeArm, left ? "LeftForeArm" : "RightForeArm", left ? LeftArm : RightArm, elbow);
        set(left ? LeftHand : RightHand, left ? "LeftHand" : "RightHand", left ? LeftForeArm : RightForeArm, wrist);
        set(left ? LeftUpLeg : RightUpLeg, left ? "LeftUpLeg" : "RightUpLeg", Hips, {side * 0.09, 0.92, 0.0});
        set(left ? LeftLeg : RightLeg, left ? "LeftLeg" : "RightLeg", left ? LeftUpLeg : RightUpLeg, {side * 0.095, 0.505, 0.005});
        set(left ? LeftFoot : RightFoot, left ? "LeftFoot" : "RightFoot", left ? LeftLeg : RightLeg, {side * 0.10, 0.085, -0.02});
        set(left ? LeftToeBase : RightToeBase, left ? "LeftToeBase" : "RightToeBase", left ? LeftFoot : RightFoot, {side * 0.10, 0.025, 0.115});
        set(left ? LeftToe_End : RightToe_End, left ? "LeftToe_End" : "RightToe_End", left ? LeftToeBase : RightToeBase, {side * 0.10, 0.025, 0.19});
    }
    return bones;
}

// ---------------------------------------------------------------------------------------
// 2. Body as a signed distance field

struct Shape {
    enum Kind { TaperedCapsule, Ellipsoid } kind;
    int bone;
    double blend_m;        // Smooth-union radius with everything before it.
    Vector3d a, b;         // Capsule ends (a) or ellipsoid centre (a).
    double radius_a = 0;   // Capsule radius at a.
    double radius_b = 0;   // Capsule radius at b.
    Matrix3d axes = Matrix3d::Identity();  // Ellipsoid: columns are its axes in model space.
    Vector3d radii = Vector3d::Ones();     // Ellipsoid semi-axes.
};

double shape_distance(const Shape& shape, const Vector3d& p) {
    if (shape.kind == Shape::TaperedCapsule) {
        const Vector3d ab = shape.b - shape.a;
        const double t = std::clamp((p - shape.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
        return (p - (shape.a + t * ab)).norm() - (shape.radius_a + t * (shape.radius_b - shape.radius_a));
    }
    // Ellipsoid: the first-order distance k0 (k0 - 1) / k1 (exact on the surface, a good
    // bound near it, which is all the smooth union and the mesher need).
    const Vector3d q = shape.axes.transpose() * (p - shape.a);
    const double k0 = q.cwiseQuotient(shape.radii).norm();
    const double k1 = q.cwiseQuotient(shape.radii.cwiseProduct(shape.radii)).norm();
    if (k1 < 1e-12) return -shape.radii.minCoeff();
    return k0 * (k0 - 1.0) / k1;
}

// Polynomial smooth minimum: equals min(a, b) when they differ by more than k.
double smooth_min(double a, double b, double k) {
    if (k <= 0) return std::min(a, b);
    const double h = std::max(k - std::abs(a - b), 0.0) / k;
    return std::min(a, b) - h * h * k * 0.25;
}

std::vector<Shape> make_body_shapes(const std::vector<AvatarBone>& bones, double s) {
    std::vector<Shape> shapes;
    auto ellipsoid = [&](int bone, double blend, Vector3d centre, Vector3d radii, Matrix3d axes = Matrix3d::Identity()) {
        Shape shape{Shape::Ellipsoid, bone, blend * s, centre * s, Vector3d::Zero()};
        shape.radii = radii * s;
        shape.axes = axes;
        shapes.push_back(shape);
    };
    // Capsule ends are given in model space already scaled (joints) or as reference-height
    // points (scaled here).
    auto capsule = [&](int bone, double blend, Vector3d a, double radius_a, Vector3d b, double radius_b) {
        Shape shape{Shape::TaperedCapsule, bone, blend * s, a, b};
        shape.radius_a = radius_a * s;
        shape.radius_b = radius_b * s;
        shapes.push_back(shape);
    };
    auto joint = [&](int bone) { return bones[bone].joint_m; };

    // Torso: pelvis and buttocks, belly, ribcage, chest, shoulder girdle.
    ellipsoid(Hips, 0.0, {0.0, 0.95, -0.005}, {0.155, 0.105, 0.105});
    ellipsoid(Hips, 0.04, {0.068, 0.895, -0.05}, {0.075, 0.085, 0.07});
    ellipsoid(Hips, 0.04, {-0.068, 0.895, -0.05}, {0.075, 0.085, 0.07});
    ellipsoid(Spine, 0.06, {0.0, 1.08, 0.0}, {0.125, 0.11, 0.092});
    ellipsoid(Spine1, 0.05, {0.0, 1.20, 0.0}, {0.14, 0.11, 0.1});
    ellipsoid(Spine2, 0.05, {0.0, 1.30, -0.005}, {0.155, 0.12, 0.105});
    ellipsoid(Spine2, 0.03, {0.07, 1.305, 0.055}, {0.07, 0.06, 0.05});
    ellipsoid(Spine2, 0.03, {-0.07, 1.305, 0.055}, {0.07, 0.06, 0.05});
    for (double side : {1.0, -1.0}) {
        const int clavicle = side > 0 ? LeftShoulder : RightShoulder;
        capsule(clavicle, 0.04, Vector3d(side * 0.03, 1.405, -0.015) * s, 0.05,
                Vector3d(side * 0.165, 1.40, -0.02) * s, 0.048);
    }
    // Neck and head (skull, jaw, nose).
    capsule(Neck, 0.04, Vector3d(0.0, 1.42, -0.015) * s, 0.056, Vector3d(0.0, 1.57, 0.0) * s, 0.05);
    ellipsoid(Head, 0.03, {0.0, 1.652, 0.0}, {0.078, 0.098, 0.095});
    ellipsoid(Head, 0.03, {0.0, 1.585, 0.03}, {0.058, 0.05, 0.065});
    ellipsoid(Head, 0.012, {0.0, 1.635, 0.095}, {0.014, 0.024, 0.022});
    for (double side : {1.0, -1.0}) {
        const bool left = side > 0;
        // Arm: the deltoid's cap, upper arm, forearm, a flat hand with the palm inwards.
        const int arm = left ? LeftArm : RightArm, fore = left ? LeftForeArm : RightForeArm,
                  hand = left ? LeftHand : RightHand;
        ellipsoid(arm, 0.05, (joint(arm) + s * Vector3d(side * 0.012, -0.045, 0.0)) / s, {0.05, 0.08, 0.052});
        capsule(arm, 0.03, joint(arm) + 0.03 * s * arm_direction(side), 0.046, joint(fore), 0.04);
        capsule(fore, 0.015, joint(fore), 0.041, joint(hand), 0.027);
        Matrix3d hand_axes;
        const Vector3d along = arm_direction(side);
        hand_axes.col(0) = Vector3d(std::cos(arm_abduction_rad), side * std::sin(arm_abduction_rad), 0.0);  // palm normal
        hand_axes.col(1) = along;
        hand_axes.col(2) = hand_axes.col(0).cross(hand_axes.col(1));
        ellipsoid(hand, 0.02, (joint(hand) + 0.08 * s * along) / s, {0.022, 0.088, 0.045}, hand_axes);
        // Leg: thigh, shin with the calf muscle, foot with heel, toes.
        const int up = left ? LeftUpLeg : RightUpLeg, leg = left ? LeftLeg : RightLeg,
                  foot = left ? LeftFoot : RightFoot, toe = left ? LeftToeBase : RightToeBase;
        const double x = joint(foot).x() / s;
        capsule(up, 0.05, joint(up), 0.088, joint(leg), 0.057);
        capsule(leg, 0.02, joint(leg), 0.054, joint(foot), 0.035);
        ellipsoid(leg, 0.03, {joint(leg).x() / s, 0.37, -0.022}, {0.05, 0.1, 0.05});
        ellipsoid(foot, 0.03, {x, 0.045, 0.035}, {0.045, 0.042, 0.1});
        ellipsoid(foot, 0.03, {x, 0.045, -0.045}, {0.038, 0.042, 0.04});
        ellipsoid(toe, 0.02, {x, 0.025, 0.145}, {0.046, 0.025, 0.045});
    }
    return shapes;
}

struct BodyField {
    std::vector<Shape> shapes;

    double operator()(const Vector3d& p) const {
        double d = shape_distance(shapes[0], p);
        for (std::size_t i = 1; i < shapes.size(); ++i) d = smooth_min(d, shape_distance(shapes[i], p), shapes[i].blend_m);
        return d;
    }
    Vector3d gradient(const Vector3d& p, double h) const {
        Vector3d g;
        for (int axis = 0; axis < 3; ++axis) {
            Vector3d e = Vector3d::Zero();
            e[axis] = h;
            g[axis] = ((*this)(p + e) - (*this)(p - e)) / (2 * h);
        }
        return g;
    }
};

// ---------------------------------------------------------------------------------------
// 3. Surface nets

struct RawMesh {
    std::vector<Vector3d> positions;
    std::vector<Vector3d> normals;
    std::vector<std::uint32_t> indices;
};

RawMesh surface_nets(const BodyField& field, double spacing) {
    // Grid over the shapes' bounds with two empty cells of margin, aligned to the spacing.
    Vector3d low = Vector3d::Constant(1e9), high = Vector3d::Constant(-1e9);
    for (const Shape& shape : field.shapes) {
        const double reach = shape.kind == Shape::Ellipsoid ? shape.radii.maxCoeff()
                                                            : std::max(shape.radius_a, shape.radius_b);
        const Vector3d b = shape.kind == Shape::Ellipsoid ? shape.a : shape.b;
        low = low.cwiseMin(shape.a.cwiseMin(b) - Vector3d::Constant(reach + shape.blend_m));
        high = high.cwiseMax(shape.a.cwiseMax(b) + Vector3d::Constant(reach + shape.blend_m));
    }
    std::array<int, 3> n{};
    Vector3d origin;
    for (int axis = 0; axis < 3; ++axis) {
        origin[axis] = (std::floor(low[axis] / spacing) - 2) * spacing;
        n[axis] = static_cast<int>(std::ceil((high[axis] - origin[axis]) / spacing)) + 3;
    }
    auto point_index = [&](int i, int j, int k) { return std::size_t(i) + std::size_t(n[0]) * (std::size_t(j) + std::size_t(n[1]) * k); };
    auto grid_point = [&](int i, int j, int k) { return Vector3d(origin.x() + i * spacing, origin.y() + j * spacing, origin.z() + k * spacing); };

    std::vector<double> value(std::size_t(n[0]) * n[1] * n[2]);
    for (int k = 0; k < n[2]; ++k)
        for (int j = 0; j < n[1]; ++j)
            for (int i = 0; i < n[0]; ++i) value[point_index(i, j, k)] = field(grid_point(i, j, k));

    // One vertex per cell the surface crosses: the mean of its edge crossings, then Newton
    // steps onto the zero set (bounded so a vertex stays near its cell).
    RawMesh mesh;
    const std::array<int, 3> cells{n[0] - 1, n[1] - 1, n[2] - 1};
    auto cell_index = [&](int i, int j, int k) { return std::size_t(i) + std::size_t(cells[0]) * (std::size_t(j) + std::size_t(cells[1]) * k); };
    std::vector<std::int32_t> cell_vertex(std::size_t(cells[0]) * cells[1] * cells[2], -1);
    const double h = spacing * 0.01;
    for (int k = 0; k < cells[2]; ++k)
        for (int j = 0; j < cells[1]; ++j)
            for (int i = 0; i < cells[0]; ++i) {
                std::array<double, 8> f;
                int inside = 0;
                for (int c = 0; c < 8; ++c) {
                    f[c] = value[point_index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))];
                    inside += f[c] < 0;
                }
                if (inside == 0 || inside == 8) continue;
                Vector3d sum = Vector3d::Zero();
                int crossings = 0;
                for (int c = 0; c < 8; ++c)
                    for (int bit : {1, 2, 4}) {
                        if (c & bit) continue;
                        const int d = c | bit;
                        if ((f[c] < 0) == (f[d] < 0)) continue;
                        const double t = f[c] / (f[c] - f[d]);
                        const Vector3d pc(c & 1, (c >> 1) & 1, (c >> 2) & 1), pd(d & 1, (d >> 1) & 1, (d >> 2) & 1);
                        sum += pc + t * (pd - pc);
                        ++crossings;
                    }
                const Vector3d start = grid_point(i, j, k) + spacing * sum / crossings;
                Vector3d v = start;
                for (int step = 0; step < 4; ++step) {
                    const Vector3d g = field.gradient(v, h);
                    const double g2 = g.squaredNorm();
                    if (g2 < 1e-12) break;
                    v -= field(v) / g2 * g;
                    const Vector3d moved = v - start;
                    if (moved.norm() > 0.6 * spacing) v = start + moved.normalized() * 0.6 * spacing;
                }
                cell_vertex[cell_index(i, j, k)] = static_cast<std::int32_t>(mesh.positions.size());
                mesh.positions.push_back(v);
                mesh.normals.push_back(field.gradient(v, h).normalized());
            }

    // One quad per grid edge the surface crosses, joining the four cells around the edge,
    // wound so that its normal points from inside to outside; split along its shorter diagonal.
    for (int k = 1; k < n[2] - 1; ++k)
        for (int j = 1; j < n[1] - 1; ++j)
            for (int i = 1; i < n[0] - 1; ++i) {
                const std::array<int, 3> p{i, j, k};
                const bool inside = value[point_index(i, j, k)] < 0;
                for (int axis = 0; axis < 3; ++axis) {
                    std::array<int, 3> q = p;
                    ++q[axis];
                    if (inside == (value[point_index(q[0], q[1], q[2])] < 0)) continue;
                    const int b = (axis + 1) % 3, c = (axis + 2) % 3;
                    std::array<std::int32_t, 4> quad;
                    const std::array<std::array<int, 2>, 4> offsets{{{-1, -1}, {0, -1}, {0, 0}, {-1, 0}}};
                    for (int corner = 0; corner < 4; ++corner) {
                        std::array<int, 3> cell = p;
                        cell[b] += offsets[corner][0];
                        cell[c] += offsets[corner][1];
                        quad[corner] = cell_vertex[cell_index(cell[0], cell[1], cell[2])];
                    }
                    if (!inside) std::swap(quad[1], quad[3]);
                    const auto& x = mesh.positions;
                    const bool first_diagonal = (x[quad[0]] - x[quad[2]]).squaredNorm() <= (x[quad[1]] - x[quad[3]]).squaredNorm();
                    const std::array<int, 6> order = first_diagonal ? std::array<int, 6>{0, 1, 2, 0, 2, 3}
                                                                    : std::array<int, 6>{0, 1, 3, 1, 2, 3};
                    for (int corner : order) mesh.indices.push_back(static_cast<std::uint32_t>(quad[corner]));
                }
            }
    return mesh;
}

// ---------------------------------------------------------------------------------------
// 4. Skin weights

void compute_skin_weights(const BodyField& field, std::size_t bone_count, double band_m, AvatarModel& model) {
    const Eigen::Index count = model.positions.cols();
    model.bone_indices.setZero(4, count);
    model.bone_weights.setZero(4, count);
    std::vector<double> bone_distance(bone_count);
    std::vector<std::pair<double, int>> candidates;
    for (Eigen::Index v = 0; v < count; ++v) {
        const Vector3d p = model.positions.col(v).cast<double>();
        std::fill(bone_distance.begin(), bone_distance.end(), 1e9);
        for (const Shape& shape : field.shapes)
            bone_distance[shape.bone] = std::min(bone_distance[shape.bone], shape_distance(shape, p));
        const double nearest = *std::min_element(bone_distance.begin(), bone_distance.end());
        candidates.clear();
        for (std::size_t bone = 0; bone < bone_count; ++bone) {
            const double u = 1.0 - (bone_distance[bone] - nearest) / band_m;
            if (u > 0) candidates.emplace_back(u * u, static_cast<int>(bone));
        }
        // Strongest first; equal weights by bone index, so the order never depends on chance.
        std::sort(candidates.begin(), candidates.end(), [](const auto& l, const auto& r) {
            return l.first != r.first ? l.first > r.first : l.second < r.second;
        });
        candidates.resize(std::min<std::size_t>(candidates.size(), 4));
        double total = 0;
        for (const auto& [w, bone] : candidates) total += w;
        for (std::size_t slot = 0; slot < candidates.size(); ++slot) {
            model.bone_indices(Eigen::Index(slot), v) = candidates[slot].second;
            model.bone_weights(Eigen::Index(slot), v) = static_cast<Real>(candidates[slot].first / total);
        }
    }
}

// ---------------------------------------------------------------------------------------
// 5. Clips

// A smooth periodic bump (von Mises) on the cycle phase: 1 at `centre`, width about `width`.
double bump(double phase, double centre, double width) {
    const double w = 2 * pi * width;
    return std::exp((std::cos(2 * pi * (phase - centre)) - 1.0) / (w * w));
}

Quaterniond about(const Vector3d& axis, double degrees) { return Quaterniond(Eigen::AngleAxisd(radians(degrees), axis.normalized())); }

struct Pose {
    std::array<Quaterniond, BoneCount> rotation;
    Vector3d hips_offset = Vector3d::Zero();  // Added to the pelvis's bind translation.
    Pose() { rotation.fill(Quaterniond::Identity()); }
};

// Gait curves of one leg at `phase` (0 = its heel strike), degrees, after the shapes of
// normal walking (hip 25 degrees of flexion at heel strike to 12 of extension before toe
// off; knee about 15 in loading and 60 in swing; ankle plantar-flexed at push-off).
struct LegAngles {
    double hip_flexion, knee_flexion, ankle_dorsiflexion, toe_extension;
};
LegAngles leg_angles(double phase) {
    return {
        6.0 + 18.0 * std::cos(2 * pi * (phase - 0.02)),
        3.0 + 14.0 * bump(phase, 0.14, 0.06) + 58.0 * bump(phase, 0.72, 0.1),
        -6.0 * bump(phase, 0.06, 0.04) + 9.0 * bump(phase, 0.42, 0.1) - 18.0 * bump(phase, 0.62, 0.05) + 4.0 * bump(phase, 0.85, 0.08),
        22.0 * bump(phase, 0.57, 0.05),
    };
}

// Walk at `phase` in [0, 1): 0 is the left heel strike, 0.5 the right.
Pose walk_pose(double phase) {
    Pose pose;
    const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY(), z = Vector3d::UnitZ();
    const double c = std::cos(2 * pi * phase), s = std::sin(2 * pi * phase);
    // Pelvis: turns its left side forward as the left leg reaches forward, lists (drops)
    // on the swing side, tilts slightly at double the cycle rate.
    const double pelvis_yaw = 4.0 * c, pelvis_list = 3.0 * s, pelvis_tilt = 1.5 * std::cos(4 * pi * phase);
    pose.rotation[Hips] = about(y, -pelvis_yaw) * about(z, pelvis_list) * about(x, pelvis_tilt);
    // Torso: the shoulders counter-rotate against the pelvis; the spine undoes the list
    // and leans a little forward; neck and head keep the gaze steady.
    const double thorax_yaw = -3.0 * c;
    const double spine_yaw = (-thorax_yaw - pelvis_yaw) / 3.0;  // Left side forward is negative about y.
    for (Bone bone : {Spine, Spine1, Spine2})
        pose.rotation[bone] = about(y, -spine_yaw) * about(z, -pelvis_list / 3.0) * about(x, bone == Spine ? 2.0 : 0.5);
    pose.rotation[Neck] = about(y, -thorax_yaw * 0.5) * about(x, -1.5);
    pose.rotation[Head] = about(y, -thorax_yaw * 0.5) * about(x, -pelvis_tilt * 0.5);
    for (double side : {1.0, -1.0}) {
        const bool left = side > 0;
        const double leg_phase = left ? phase : std::fmod(phase + 0.5, 1.0);
        const LegAngles leg = leg_angles(leg_phase);
        // Flexion moves the distal end forward (+z): a negative turn about +x.
        pose.rotation[left ? LeftUpLeg : RightUpLeg] = about(x, -leg.hip_flexion) * about(z, side * -1.0);
        pose.rotation[left ? LeftLeg : RightLeg] = about(x, leg.knee_flexion);
        pose.rotation[left ? LeftFoot : RightFoot] = about(x, -leg.ankle_dorsiflexion);
        pose.rotation[left ? LeftToeBase : RightToeBase] = about(x, -leg.toe_extension);
        // Arm swings opposite to the leg on its side; the elbow bends more when forward.
        const double swing = -std::cos(2 * pi * leg_phase);  // +1: arm forward.
        const Vector3d bend_axis(std::cos(arm_abduction_rad), side * std::sin(arm_abduction_rad), 0.0);
        pose.rotation[left ? LeftArm : RightArm] = about(bend_axis, -(3.0 + 15.0 * swing));
        pose.rotation[left ? LeftForeArm : RightForeArm] = about(bend_axis, -(16.0 + 10.0 * swing));
        pose.rotation[left ? LeftHand : RightHand] = about(bend_axis, -4.0);
        pose.rotation[left ? LeftShoulder : RightShoulder] = about(x, -1.5 * swing);
    }
    return pose;
}

// Idle at `phase` in [0, 1) of a 4 s cycle: slow breathing, a small weight shift, relaxed arms.
Pose idle_pose(double phase) {
    Pose pose;
    const Vector3d x = Vector3d::UnitX(), y = Vector3d::UnitY(), z = Vector3d::UnitZ();
    const double breath = std::sin(2 * pi * phase), sway = std::sin(2 * pi * phase + 0.6);
    pose.hips_offset = Vector3d(0.008 * sway, 0.0, 0.0);
    pose.rotation[Hips] = about(z, 1.0 * sway);
    pose.rotation[Spine] = about(z, -0.6 * sway);
    pose.rotation[Spine1] = about(x, -0.8 * breath);
    pose.rotation[Spine2] = about(x, -0.8 * breath) * about(z, -0.4 * sway);
    pose.rotation[Neck] = about(x, 0.8 * breath);
    pose.rotation[Head] = about(y, 3.0 * std::sin(2 * pi * phase + 1.0)) * about(x, 0.5 * breath);
    for (double side : {1.0, -1.0}) {
        const bool left = side > 0;
        const Vector3d bend_axis(std::cos(arm_abduction_rad), side * std::sin(arm_abduction_rad), 0.0);
        pose.rotation[left ? LeftShoulder : RightShoulder] = about(z, side * 1.0 * breath);
        pose.rotation[left ? LeftArm : RightArm] = about(bend_axis, -3.0) * about(z, side * -0.5 * breath);
        pose.rotation[left ? LeftForeArm : RightForeArm] = about(bend_axis, -10.0);
        // Legs counter the pelvis's roll so the feet stay level.
        pose.rotation[left ? LeftUpLeg : RightUpLeg] = about(z, -1.0 * sway);
    }
    return pose;
}

// Model-space transforms of every bone for a pose (bind frames carry no rotation).
std::array<Eigen::Isometry3d, BoneCount> global_transforms(const std::vector<AvatarBone>& bones, const Pose& pose) {
    std::array<Eigen::Isometry3d, BoneCount> global;
    for (int bone = 0; bone < BoneCount; ++bone) {
        const int parent = bones[bone].parent;
        Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
        local.translation() = bones[bone].joint_m - (parent >= 0 ? bones[parent].joint_m : Vector3d::Zero());
        if (bone == Hips) local.translation() += pose.hips_offset;
        local.linear() = pose.rotation[bone].toRotationMatrix();
        global[bone] = parent >= 0 ? global[parent] * local : local;
    }
    return global;
}

// Lowest point of the soles (heel, ball, toe tip of each foot) for a pose, metres.
double lowest_sole_height(const std::vector<AvatarBone>& bones, const Pose& pose, double s) {
    const auto global = global_transforms(bones, pose);
    double lowest = 1e9;
    for (double side : {1.0, -1.0}) {
        const int foot = side > 0 ? LeftFoot : RightFoot, toe = side > 0 ? LeftToeBase : RightToeBase;
        const double x = bones[foot].joint_m.x();
        const std::array<std::pair<int, Vector3d>, 3> soles{{
            {foot, Vector3d(x, 0.0, -0.08 * s)}, {toe, Vector3d(x, 0.0, 0.115 * s)}, {toe, Vector3d(x, 0.0, 0.19 * s)}}};
        for (const auto& [bone, point] : soles)
            lowest = std::min(lowest, (global[bone] * (point - bones[bone].joint_m)).y());
    }
    return lowest;
}

template <class PoseAt>
AvatarClip make_clip(std::string name, double period_s, const std::vector<AvatarBone>& bones, double s,
                     int keys_per_second, PoseAt pose_at) {
    AvatarClip clip;
    clip.name = std::move(name);
    clip.keys_per_second = keys_per_second;
    const int frames = std::max(2, static_cast<int>(std::lround(period_s * keys_per_second)));
    const double bind_sole = lowest_sole_height(bones, Pose{}, s);
    for (int frame = 0; frame < frames; ++frame) {
        Pose pose = pose_at(double(frame) / frames);
        // Pelvis height: the lowest sole point rests on the floor, as it does at bind.
        pose.hips_offset.y() += bind_sole - lowest_sole_height(bones, pose, s);
        std::vector<Vector3d> translations(BoneCount);
        std::vector<Quaterniond> rotations(BoneCount);
        for (int bone = 0; bone < BoneCount; ++bone) {
            const int parent = bones[bone].parent;
            translations[bone] = bones[bone].joint_m - (parent >= 0 ? bones[parent].joint_m : Vector3d::Zero());
            if (bone == Hips) translations[bone] += pose.hips_offset;
            Quaterniond q = pose.rotation[bone].normalized();
            if (q.w() < 0) q.coeffs() = -q.coeffs();  // One hemisphere: keys slerp the short way.
            rotations[bone] = q;
        }
        clip.translations.push_back(std::move(translations));
        clip.rotations.push_back(std::move(rotations));
    }
    // The last key repeats the first exactly: the clip loops without a seam.
    clip.translations.push_back(clip.translations.front());
    clip.rotations.push_back(clip.rotations.front());
    return clip;
}

// ---------------------------------------------------------------------------------------
// 6. assimp scene

aiMatrix4x4 translation_matrix(const Vector3d& t) {
    aiMatrix4x4 m;
    aiMatrix4x4::Translation(aiVector3D(ai_real(t.x()), ai_real(t.y()), ai_real(t.z())), m);
    return m;
}

}  // namespace

int AvatarModel::find_bone(std::string_view name) const noexcept {
    for (std::size_t i = 0; i < bones.size(); ++i)
        if (bones[i].name == name) return static_cast<int>(i);
    return -1;
}

AvatarModel make_default_avatar(const AvatarOptions& options) {
    const double s = options.height_m / reference_height_m;
    AvatarModel model;
    model.bones = make_skeleton(s);
    const BodyField field{make_body_shapes(model.bones, s)};
    const RawMesh mesh = surface_nets(field, options.grid_spacing_m * s);
    const Eigen::Index count = static_cast<Eigen::Index>(mesh.positions.size());
    model.positions.resize(3, count);
    model.normals.resize(3, count);
    for (Eigen::Index v = 0; v < count; ++v) {
        model.positions.col(v) = mesh.positions[std::size_t(v)].cast<Real>();
        model.normals.col(v) = mesh.normals[std::size_t(v)].cast<Real>();
    }
    model.indices = mesh.indices;
    compute_skin_weights(field, model.bones.size(), 0.045 * s, model);
    const int fps = std::max(1, options.keys_per_second);
    model.clips.push_back(make_clip("Walk", 1.1, model.bones, s, fps, walk_pose));
    model.clips.push_back(make_clip("Idle", 4.0, model.bones, s, fps, idle_pose));
    return model;
}

std::unique_ptr<aiScene> to_assimp_scene(const AvatarModel& model) {
    auto scene = std::make_unique<aiScene>();

    scene->mNumMaterials = 1;
    scene->mMaterials = new aiMaterial*[1];
    scene->mMaterials[0] = new aiMaterial();
    const aiString material_name("Skin");
    scene->mMaterials[0]->AddProperty(&material_name, AI_MATKEY_NAME);
    const aiColor4D skin(0.72f, 0.56f, 0.46f, 1.0f);
    scene->mMaterials[0]->AddProperty(&skin, 1, AI_MATKEY_COLOR_DIFFUSE);

    // Mesh with its skin: one aiBone per joint, weights listed in vertex order.
    auto* mesh = new aiMesh();
    mesh->mName = aiString("Body");
    mesh->mMaterialIndex = 0;
    mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    const unsigned vertex_count = static_cast<unsigned>(model.positions.cols());
    mesh->mNumVertices = vertex_count;
    mesh->mVertices = new aiVector3D[vertex_count];
    mesh->mNormals = new aiVector3D[vertex_count];
    for (unsigned v = 0; v < vertex_count; ++v) {
        mesh->mVertices[v] = aiVector3D(model.positions(0, v), model.positions(1, v), model.positions(2, v));
        mesh->mNormals[v] = aiVector3D(model.normals(0, v), model.normals(1, v), model.normals(2, v));
    }
    const unsigned face_count = static_cast<unsigned>(model.triangle_count());
    mesh->mNumFaces = face_count;
    mesh->mFaces = new aiFace[face_count];
    for (unsigned f = 0; f < face_count; ++f) {
        mesh->mFaces[f].mNumIndices = 3;
        mesh->mFaces[f].mIndices = new unsigned[3]{model.indices[3 * f], model.indices[3 * f + 1], model.indices[3 * f + 2]};
    }
    const unsigned bone_count = static_cast<unsigned>(model.bones.size());
    std::vector<std::vector<aiVertexWeight>> weights(bone_count);
    for (unsigned v = 0; v < vertex_count; ++v)
        for (int slot = 0; slot < 4; ++slot)
            if (model.bone_weights(slot, v) > 0)
                weights[std::size_t(model.bone_indices(slot, v))].emplace_back(v, model.bone_weights(slot, v));
    // Skin joints: the bones that carry weight. The leaf markers (HeadTop_End, *Toe_End)
    // stay plain nodes: assimp's glTF reader would give a weightless joint a dummy weight.
    std::vector<unsigned> joints;
    for (unsigned b = 0; b < bone_count; ++b)
        if (!weights[b].empty()) joints.push_back(b);
    mesh->mNumBones = static_cast<unsigned>(joints.size());
    mesh->mBones = new aiBone*[joints.size()];
    for (std::size_t j = 0; j < joints.size(); ++j) {
        const unsigned b = joints[j];
        auto* bone = new aiBone();
        bone->mName = aiString(model.bones[b].name);
        bone->mOffsetMatrix = translation_matrix(-model.bones[b].joint_m);  // Inverse bind: bind frames are translations.
        bone->mNumWeights = static_cast<unsigned>(weights[b].size());
        bone->mWeights = new aiVertexWeight[weights[b].size()];
        std::copy(weights[b].begin(), weights[b].end(), bone->mWeights);
        mesh->mBones[j] = bone;
    }
    scene->mNumMeshes = 1;
    scene->mMeshes = new aiMesh*[1]{mesh};

    // Nodes: a root holding the body and the skeleton.
    scene->mRootNode = new aiNode("Avatar");
    auto* body = new aiNode("Body");
    body->mNumMeshes = 1;
    body->mMeshes = new unsigned[1]{0};
    std::vector<aiNode*> nodes(bone_count);
    std::vector<std::vector<aiNode*>> children(bone_count);
    for (unsigned b = 0; b < bone_count; ++b) {
        const AvatarBone& bone = model.bones[b];
        nodes[b] = new aiNode(bone.name);
        nodes[b]->mTransformation = translation_matrix(bone.joint_m - (bone.parent >= 0 ? model.bones[std::size_t(bone.parent)].joint_m : Vector3d::Zero()));
        if (bone.parent >= 0) children[std::size_t(bone.parent)].push_back(nodes[b]);
    }
    for (unsigned b = 0; b < bone_count; ++b)
        if (!children[b].empty()) nodes[b]->addChildren(static_cast<unsigned>(children[b].size()), children[b].data());
    std::array<aiNode*, 2> top{body, nodes[0]};
    scene->mRootNode->addChildren(2, top.data());

    // One animation per clip; every bone with children gets translation and rotation keys
    // at every frame and a single unit scale key.
    scene->mNumAnimations = static_cast<unsigned>(model.clips.size());
    scene->mAnimations = new aiAnimation*[model.clips.size()];
    for (std::size_t c = 0; c < model.clips.size(); ++c) {
        const AvatarClip& clip = model.clips[c];
        auto* animation = new aiAnimation();
        animation->mName = aiString(clip.name);
        animation->mTicksPerSecond = clip.keys_per_second;
        animation->mDuration = clip.frame_count() - 1;  // Ticks: one per frame.
        std::vector<unsigned> animated;
        for (unsigned b = 0; b < bone_count; ++b)
            if (!children[b].empty()) animated.push_back(b);
        animation->mNumChannels = static_cast<unsigned>(animated.size());
        animation->mChannels = new aiNodeAnim*[animated.size()];
        const unsigned frames = static_cast<unsigned>(clip.frame_count());
        for (std::size_t a = 0; a < animated.size(); ++a) {
            const unsigned b = animated[a];
            auto* channel = new aiNodeAnim();
            channel->mNodeName = aiString(model.bones[b].name);
            channel->mNumPositionKeys = frames;
            channel->mPositionKeys = new aiVectorKey[frames];
            channel->mNumRotationKeys = frames;
            channel->mRotationKeys = new aiQuatKey[frames];
            for (unsigned f = 0; f < frames; ++f) {
                const Vector3d& t = clip.translations[f][b];
                const Quaterniond& q = clip.rotations[f][b];
                channel->mPositionKeys[f] = aiVectorKey(f, aiVector3D(ai_real(t.x()), ai_real(t.y()), ai_real(t.z())));
                channel->mRotationKeys[f] = aiQuatKey(f, aiQuaternion(ai_real(q.w()), ai_real(q.x()), ai_real(q.y()), ai_real(q.z())));
            }
            channel->mNumScalingKeys = 1;
            channel->mScalingKeys = new aiVectorKey[1]{aiVectorKey(0.0, aiVector3D(1, 1, 1))};
            animation->mChannels[a] = channel;
        }
        scene->mAnimations[c] = animation;
    }
    return scene;
}

namespace {

Result<void> check(const AvatarOptions& options) {
    if (!(options.height_m >= 0.5 && options.height_m <= 3.0))
        return fail("avatar options: height_m must be between 0.5 and 3 m");
    if (!(options.grid_spacing_m >= 0.005 && options.grid_spacing_m <= 0.05))
        return fail("avatar options: grid_spacing_m must be between 0.005 and 0.05 m");
    if (options.keys_per_second < 1 || options.keys_per_second > 240)
        return fail("avatar options: keys_per_second must be between 1 and 240");
    return {};
}

// assimp 5.2.5's glb2 writer converts JOINTS_0 from float to 16-bit indices in place and
// leaves the second half of the old float range in the binary chunk, unreferenced and
// uninitialised (Buffer::ReplaceData_joint copies a half-filled scratch array). Zeroing
// every byte of the binary chunk that no bufferView covers makes the file deterministic
// without changing what any reader sees.
Result<void> zero_unreferenced_bytes(std::vector<std::uint8_t>& glb) {
    auto u32 = [&](std::size_t at) {
        std::uint32_t v = 0;
        for (int i = 3; i >= 0; --i) v = (v << 8) | glb[at + std::size_t(i)];
        return v;
    };
    constexpr std::uint32_t magic = 0x46546C67, json_chunk = 0x4E4F534A, bin_chunk = 0x004E4942;  // "glTF", "JSON", "BIN\0"
    if (glb.size() < 20 || u32(0) != magic || u32(4) != 2 || u32(8) != glb.size() || u32(16) != json_chunk)
        return fail("avatar: assimp's glb2 output is not a binary glTF 2.0 file");
    const std::size_t json_length = u32(12);
    const std::size_t bin_header = 20 + json_length;
    if (bin_header == glb.size()) return {};  // No binary chunk.
    if (bin_header + 8 > glb.size() || u32(bin_header + 4) != bin_chunk)
        return fail("avatar: assimp's glb2 output has no well-formed binary chunk");
    const std::size_t bin_start = bin_header + 8, bin_length = std::min<std::size_t>(u32(bin_header), glb.size() - bin_start);
    const auto json = nlohmann::json::parse(glb.begin() + 20, glb.begin() + std::ptrdiff_t(bin_header), nullptr, false);
    if (json.is_discarded() || !json.contains("bufferViews")) return fail("avatar: assimp's glb2 output has unreadable JSON");
    std::vector<bool> used(bin_length, false);
    for (const auto& view : json["bufferViews"]) {
        if (view.value("buffer", 0) != 0) continue;
        const std::size_t offset = view.value("byteOffset", std::size_t(0)), length = view.value("byteLength", std::size_t(0));
        for (std::size_t i = offset; i < std::min(offset + length, bin_length); ++i) used[i] = true;
    }
    for (std::size_t i = 0; i < bin_length; ++i)
        if (!used[i]) glb[bin_start + i] = 0;
    return {};
}

}  // namespace

Result<std::vector<std::uint8_t>> avatar_glb(const AvatarModel& model) {
    const std::unique_ptr<aiScene> scene = to_assimp_scene(model);
    Assimp::Exporter exporter;
    const aiExportDataBlob* blob = exporter.ExportToBlob(scene.get(), "glb2");
    if (blob == nullptr) return fail(std::string("avatar: assimp glb2 export failed: ") + exporter.GetErrorString());
    const auto* data = static_cast<const std::uint8_t*>(blob->data);
    std::vector<std::uint8_t> bytes(data, data + blob->size);
    if (auto clean = zero_unreferenced_bytes(bytes); !clean) return std::unexpected(clean.error());
    return bytes;
}

Result<std::vector<std::uint8_t>> default_avatar_glb(const AvatarOptions& options) {
    if (auto valid = check(options); !valid) return std::unexpected(valid.error());
    return avatar_glb(make_default_avatar(options));
}

Result<void> write_avatar(const AvatarModel& model, const std::filesystem::path& path) {
    const std::filesystem::path folder = path.parent_path();
    std::error_code error;
    if (!folder.empty() && !std::filesystem::is_directory(folder, error))
        return fail(path.string() + ": cannot write, folder " + folder.string() + " does not exist");
    if (std::filesystem::is_directory(path, error)) return fail(path.string() + ": is a folder, not a file");
    auto bytes = avatar_glb(model);
    if (!bytes) return std::unexpected(bytes.error());
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) return fail(path.string() + ": cannot open for writing");
    out.write(reinterpret_cast<const char*>(bytes->data()), static_cast<std::streamsize>(bytes->size()));
    out.close();
    if (!out) return fail(path.string() + ": write failed");
    return {};
}

Result<void> write_default_avatar(const std::filesystem::path& path, const AvatarOptions& options) {
    if (auto valid = check(options); !valid) return std::unexpected(valid.error());
    return write_avatar(make_default_avatar(options), path);
}

}  // namespace drape
