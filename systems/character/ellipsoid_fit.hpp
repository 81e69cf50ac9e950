// Automatic bone-bound ellipsoids for any skinned character (method §2), and how well
// they cover the body.
//
// Fitting, per bone: take the vertices that bone dominates by skin weight, in the bone's
// frame at bind; bones with too few vertices or too small a cluster hand their vertices to
// their parent (fingers merge into the hand, a toe into the foot); each remaining cluster
// gets an ellipsoid whose axes are the cluster's principal axes, centred on its bounding
// box in that frame, scaled so that `cluster_coverage` of the cluster's vertices lie inside.
// Hands and feet get one ellipsoid each. Above `max_ellipsoids`, the child cluster whose
// joint moves least in the clips merges into its parent first (with its left/right partner).
//
// Coverage (the acceptance measure): the share of body vertices inside some ellipsoid or
// within `tolerance_m` of one. Bulge: how far ellipsoid surfaces stand out of the body,
// measured at sample points on each surface against the nearest body vertex and its normal.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "components/ellipsoid_collider.hpp"
#include "engine/assets/animation_clip.hpp"
#include "engine/assets/mesh_asset.hpp"
#include "engine/assets/skeleton_asset.hpp"
#include "engine/core/error.hpp"
#include "engine/core/math.hpp"

namespace drape {

struct FitOptions {
    double min_cluster_fraction = 0.004;   ///< A bone with fewer of the vertices than this merges into its parent.
    double min_cluster_size = 0.09;        ///< ... or whose cluster is shorter than this share of the height.
    double cluster_coverage = 0.97;        ///< Share of a cluster's vertices an ellipsoid must hold.
    double min_radius_m = 0.01;            ///< No axis thinner than this.
    int max_ellipsoids = 16;               ///< Budget (the paper's avatar has 15); 0 = one per surviving cluster.
};

/// Checks the options; the error names the field.
[[nodiscard]] Result<void> validate(const FitOptions& options);

/// Guesses a body region from a bone name ("LeftUpLeg", "thigh.L", "Spine2", ...).
[[nodiscard]] BodyRegion region_from_bone_name(std::string_view name) noexcept;

/// The pelvis bone: a bone named like hips/pelvis, else the highest bone from which two
/// leg-like branches hang. -1 when there is none. The skirt builder finds the waist here.
[[nodiscard]] int find_hip_bone(const SkeletonAsset& skeleton);

/// Bone of each vertex: the index with the largest weight.
[[nodiscard]] std::vector<int> dominant_bones(const MeshAsset& mesh);

/// Fits ellipsoids to the mesh at bind. `height_m` sets the scale of "small" clusters;
/// `clips` tell which joints move (stiff ones merge first when over budget).
[[nodiscard]] std::vector<EllipsoidShape> fit_ellipsoids(const SkeletonAsset& skeleton, const MeshAsset& mesh,
                                                         Real height_m, const FitOptions& options = {},
                                                         std::span<const std::shared_ptr<const AnimationClip>> clips = {});

/// An ellipsoid's unit sphere -> the space of `bone_global` (rigid part of the bone used).
[[nodiscard]] Affine3 ellipsoid_transform(const EllipsoidShape& shape, const Affine3& bone_global);

/// Distance from a point outside the ellipsoid (unit sphere -> space transform `e`) to its
/// surface, approximated along the ray from the centre; 0 inside.
[[nodiscard]] Real outside_distance(const Affine3& e, const Vec3& point);

struct CoverageReport {
    std::size_t vertices = 0;
    std::size_t covered = 0;          ///< Inside or within tolerance of some ellipsoid.
    double coverage = 0;              ///< covered / vertices.
    double tolerance_m = 0.01;
    double max_gap_m = 0;             ///< Largest distance of an uncovered vertex to the nearest ellipsoid.
    double mean_bulge_m = 0;          ///< Mean over surface samples that stand outside the body.
    double p95_bulge_m = 0;
    double max_bulge_m = 0;
    std::vector<double> bulge_per_ellipsoid_m;  ///< Max per ellipsoid.
};

/// Coverage and bulge of ellipsoids on a posed body: `positions`/`normals` in model space,
/// `global` the bone transforms of the same pose.
[[nodiscard]] CoverageReport measure_coverage(std::span<const EllipsoidShape> shapes, std::span<const Affine3> global,
                                              const Matrix3X& positions, const Matrix3X& normals,
                                              double tolerance_m = 0.01);

/// Reads manual ellipsoids from JSON text: an array of
/// `{"bone": "Hips", "center": [x,y,z], "radii_m": [a,b,c], "rotation": [x,y,z,w], "region": "pelvis"}`
/// (rotation and region optional). `source` names the text in errors (a scene file path).
[[nodiscard]] Result<std::vector<EllipsoidShape>> ellipsoids_from_json(std::string_view json_text,
                                                                      const SkeletonAsset& skeleton,
                                                                      std::string_view source);

/// Applies overrides to fitted shapes: an override replaces the fitted shapes of its bone,
/// or is added when the bone had none. With `replace_all`, only the overrides remain.
[[nodiscard]] std::vector<EllipsoidShape> apply_overrides(std::span<const EllipsoidShape> fitted,
                                                          std::span<const EllipsoidShape> overrides,
                                                          bool replace_all = false);

}  // namespace drape
