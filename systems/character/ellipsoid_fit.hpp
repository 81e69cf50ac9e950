// Automatic bone-bound ellipsoids for any skinned character (method §2), and how well
// they fit the body.
//
// Parts: each vertex belongs to the bone with its largest skin weight; bones with too few
// vertices or too small a cluster hand theirs to their parent (fingers merge into the
// hand, a toe into the foot), a hand or a foot is one part. Above the budget, the part
// whose joint moves least in the clips merges into its parent first (with its left/right
// partner). A bone that carries several separate rigid objects (a robot's ball joints and
// plates) gives each sizeable object a part of its own.
//
// Fitting (ellipsoid_solver.hpp): the skin at the rest pose is sampled (every vertex, plus
// points inside faces larger than the sample spacing); each part starts as one ellipsoid,
// fitted so that the union of all ellipsoids covers the samples while standing out of the
// skin as little as possible. Where one ellipsoid cannot hug the trunk (a torso, a pelvis,
// a head) more are added on the same bone, up to `max_ellipsoids`; a limb (arm, hand,
// leg, foot) keeps one ellipsoid per bone: thin pieces on a limb overlap in creases at
// the knee and the hip where the cloth's hem catches. With `arm_reach_m` (an option, off
// by default) an upper or lower arm's ellipsoid may not reach more than that past its own
// skin along the arm: without it a forearm's tip hides inside the upper arm and the hand
// at the rest pose (forearms 43-70 cm long on the characters measured) and stands into the
// armpit and the hip once the arm hangs and bends.
// Shapes are stored in the rigid frame of their bone at the rest pose.
//
// The legs (LegFit): fitted tight, each leg bone gets one ellipsoid fitted like the rest,
// which may not reach more than `leg_reach_m` past its own skin along the leg
// (ellipsoid_solver.hpp, "reach": a shin's tip hidden inside the thigh at the rest pose
// would stand out behind the bent knee), and each knee a sphere on the shin's joint
// (`knee_radius_share` x the joint's distance to the nearest leg skin), as capsule chains
// put a sphere at every joint: without it the crease the two ellipsoids leave behind the
// knee closes on a hem as the knee bends (a dress on the long-legged build: worst spring
// 256 %, 10.0 % with the spheres). Bounded, each leg bone keeps the ellipsoid that bounds
// its vertices (principal axes, 97 % of them inside), which stands out of the skin by
// several centimetres, most between the thighs. By default (automatic) the legs are fitted
// tight where the whole fit then covers the skin at the rest pose (covers_skin: 99 % of the
// vertices within 1 cm), else bounded: the humans fitted so far are covered (99.9-100 %,
// p95 bulge 1.6-2.0 cm against 3.5-7.3 cm bounded); RobotExpressive is not either way
// (97.2 %, its plates), and its dress holds its springs on the bounded legs (docs/cloth.md,
// "Known limits"). The bulge is not part of the choice: a fit near its target is decided
// by rounding. A tight fit may use `tight_extra_ellipsoids` more pieces than the budget:
// with the legs hugged the trunk's pieces decide the bulge. Up to a centimetre of thigh
// skin lies outside the tight ellipsoids; the skin cover system draws it inside them
// (systems/skin_cover_system.hpp).
//
// Give: each forearm and hand gives by its bulge over the skin at the rest pose (the
// largest, bulge_per_ellipsoid_m; EllipsoidCollider::give_m), every other piece none.
//
// Measures (measure_coverage):
//  - coverage: the share of skin vertices inside some ellipsoid or within `tolerance_m` of
//    one (the exact distance to the ellipsoid's surface);
//  - bulge: how far the surface the cloth collides with, the union of the ellipsoids,
//    stands out of the skin. Each ellipsoid's surface is sampled at 512 points (a
//    Fibonacci lattice on the unit sphere mapped onto it, each weighted by the area it
//    stands for); a point inside another ellipsoid is not on the union's surface and is
//    skipped. A point stands out when it lies on the outer side of the skin at the
//    closest point of the skin's triangles (the side the interpolated vertex normal points
//    to); its bulge is its distance to that closest point. Reported: the share of the
//    union's area that stands out, and the area-weighted mean, 95th percentile and
//    maximum bulge of the part that stands out.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/engine/assets/animation_clip.hpp"
#include "drape/engine/assets/character_asset.hpp"
#include "drape/engine/assets/mesh_asset.hpp"
#include "drape/engine/assets/skeleton_asset.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// How the legs are fitted (see the header comment).
enum class LegFit : std::uint8_t {
    automatic,  ///< Tight where the whole fit then covers the skin (covers_skin), else bounding.
    tight,      ///< One ellipsoid per leg bone fitted to the skin, its reach along the leg limited.
    bounding,   ///< One ellipsoid per leg bone bounding its vertices.
};

/// Trunk shells at most this thin are thickened inward by default (FitOptions::thicken_thin_trunk_m):
/// the thickness of the pieces the motion suite's torn runs straddled (docs/cloth.md, "Collision").
/// Built-in garments leave the trunk's pieces still this thin out of their collision
/// (TubeParams::thin_trunk_piece_m).
inline constexpr double default_thicken_thin_trunk_m = 0.015;

/// How ellipsoids are fitted (the numeric details are ellipsoid_solver.hpp's).
struct FitOptions {
    double min_cluster_fraction = 0.004;   ///< A bone with fewer of the vertices than this merges into its parent.
    double min_cluster_size = 0.09;        ///< ... or whose cluster is shorter than this share of the height.
    double tolerance_m = 0.01;             ///< A skin point this close to an ellipsoid is covered.
    double bulge_limit_m = 0.02;           ///< Surface standing out of the skin farther than this fails (asks for a split); the p95 bulge target.
    double target_coverage = 0.99;         ///< Share of skin vertices within tolerance_m of the ellipsoids the fit aims for.
    double sample_spacing = 0.016;         ///< Skin samples inside large faces at most this share of the height apart.
    double min_radius_m = 0.01;            ///< No axis thinner than this (1.25-2 cm measured and not kept: docs/cloth.md, Tried).
    int max_ellipsoids = 32;               ///< Budget of fitted pieces (the paper's avatar has 15, a garment takes 64), knee spheres on top; 0 = no limit.
    int tight_extra_ellipsoids = 2;        ///< With tight legs the budget grows by this many pieces (the trunk's decide the bulge).
    double leg_reach_m = 0.05;             ///< A hugged leg's ellipsoid may pass its own skin along the leg by this much (< 0: no limit).
    double arm_reach_m = -1;               ///< An upper or lower arm's ellipsoid may pass its own skin along the arm by this much (< 0, the default: no limit; docs/cloth.md, "Body fit").
    LegFit legs = LegFit::automatic;       ///< How the legs are fitted (see the header comment).
    double knee_radius_share = 1.2;        ///< Tight legs: a sphere at each knee, this x the joint's distance to the nearest leg skin (0: none).
    double thicken_thin_trunk_m = default_thicken_thin_trunk_m;  ///< > 0: trunk shells at most this thin are thickened inward to the thick ones (thicken_thin_trunk_pieces; 0: none).
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

/// Trunk pieces (torso, pelvis) at most FitOptions::thicken_thin_trunk_m thin whose middle
/// radius is at least twice the thin one are shells under the skin (smaller balls and rods
/// are left as they are); between one and the thick trunk pieces lies body that no ellipsoid
/// covers, where cloth that slips in past the shell's edge is held on both of its faces (a
/// spring across the shell). Each is made thicker along its thin axis, inward (away from the
/// way the skin within `tolerance_m` of it faces, by its normals), until its inner face is
/// `tolerance_m` inside the first thick trunk piece met going inward from its centre (up to
/// 12 cm; none met, or the skin's facing unknown: unchanged): thin radius r0 + k, centre k
/// inward, 2 k + r0 = that depth + tolerance_m. Its outer face's middle stays; off the
/// middle the new face lies under the old one (at most k under it at the rim). `global`:
/// the bones' rest pose; `positions`, `normals`: the skin there.
void thicken_thin_trunk_pieces(std::vector<EllipsoidShape>& shapes, std::span<const Affine3> global, const Matrix3X& positions,
                               const Matrix3X& normals, const FitOptions& options);

/// Fits ellipsoids to the skin at the skeleton's rest pose. `height_m` sets the scale of
/// "small" clusters and of the sample spacing; `clips` tell which joints move (stiff ones
/// merge first when over budget); `meshes` (CharacterAsset::meshes) tell which vertices
/// belong to rigid objects. `legs`, when given, receives the leg fit used (tight or
/// bounding; with LegFit::automatic the tight fit is made first, and the bounding one too
/// when the tight one does not cover the skin: covers_skin). Deterministic: the same input
/// gives the same shapes.
[[nodiscard]] std::vector<EllipsoidShape> fit_ellipsoids(const SkeletonAsset& skeleton, const MeshAsset& mesh,
                                                         Real height_m, const FitOptions& options = {},
                                                         std::span<const std::shared_ptr<const AnimationClip>> clips = {},
                                                         std::span<const MeshInfo> meshes = {}, LegFit* legs = nullptr);

/// An ellipsoid's unit sphere -> the space of `bone_global` (rigid part of the bone used).
[[nodiscard]] Affine3 ellipsoid_transform(const EllipsoidShape& shape, const Affine3& bone_global);

/// Distance from a point outside the ellipsoid (unit sphere -> space transform `e`, a
/// rotation times a scaling) to its surface, exact; 0 inside.
[[nodiscard]] Real outside_distance(const Affine3& e, const Vec3& point);

/// How ellipsoids fit a posed skin (see the header comment for the definitions).
struct CoverageReport {
    std::size_t vertices = 0;
    std::size_t covered = 0;          ///< Inside or within tolerance of some ellipsoid.
    double coverage = 0;              ///< covered / vertices.
    double tolerance_m = 0.01;
    double max_gap_m = 0;             ///< Largest distance of an uncovered vertex to the nearest ellipsoid.
    double surface_m2 = 0;            ///< Area of the union of the ellipsoids' surfaces.
    double outside_share = 0;         ///< Share of that area standing out of the skin.
    double mean_bulge_m = 0;          ///< Over the area standing out, area-weighted.
    double p95_bulge_m = 0;
    double max_bulge_m = 0;
    std::vector<double> bulge_per_ellipsoid_m;  ///< Max per ellipsoid (of its part of the union's surface).
};

/// Coverage and bulge of ellipsoids on a posed body: `positions`/`normals` in model space,
/// `triangles` the skin's faces (three vertex indices each, MeshAsset::indices), `global`
/// the bone transforms of the same pose.
[[nodiscard]] CoverageReport measure_coverage(std::span<const EllipsoidShape> shapes, std::span<const Affine3> global,
                                              const Matrix3X& positions, const Matrix3X& normals,
                                              std::span<const std::uint32_t> triangles, double tolerance_m = 0.01);

/// Whether a fit's coverage report meets the targets of `options`: it covers the skin
/// (covers_skin) and its p95 bulge is at most bulge_limit_m.
[[nodiscard]] bool meets_fit_targets(const CoverageReport& report, const FitOptions& options) noexcept;

/// Whether a fit covers the skin: at least target_coverage of the vertices within the
/// report's tolerance. LegFit::automatic fits the legs tight where this holds.
[[nodiscard]] bool covers_skin(const CoverageReport& report, const FitOptions& options) noexcept;

/// "automatic", "tight", "bounding".
[[nodiscard]] const char* leg_fit_name(LegFit legs) noexcept;

/// Reads manual ellipsoids from JSON text: an array of
/// `{"bone": "Hips", "center": [x,y,z], "radii_m": [a,b,c], "rotation": [x,y,z,w], "region": "pelvis", "give_m": 0}`
/// (rotation, region and give optional; give_m in [0, 0.5] m as in scene files: EllipsoidCollider::give_m, none by default). `source` names the text in errors (a scene file path).
[[nodiscard]] Result<std::vector<EllipsoidShape>> ellipsoids_from_json(std::string_view json_text,
                                                                      const SkeletonAsset& skeleton,
                                                                      std::string_view source);

/// Applies overrides to fitted shapes: an override replaces the fitted shapes of its bone,
/// or is added when the bone had none. With `replace_all`, only the overrides remain.
[[nodiscard]] std::vector<EllipsoidShape> apply_overrides(std::span<const EllipsoidShape> fitted,
                                                          std::span<const EllipsoidShape> overrides,
                                                          bool replace_all = false);

}  // namespace drape
