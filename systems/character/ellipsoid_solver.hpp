// The numeric core of ellipsoid fitting (method §2): ellipsoids in model space fitted to
// sample points of a posed skin, so that their union covers the skin and stands out of it
// as little as possible. ellipsoid_fit.hpp turns the result into bone-bound shapes.
//
// Each ellipsoid ("piece") starts from one part of the body (the skin samples of one bone's
// cluster): its principal axes and the box they span. Fitting a piece minimises, by
// Levenberg-Marquardt over its centre, orientation and log radii, a sum of squared,
// Huber-softened residuals:
//   - cover, per nearby skin sample the piece answers for (the one piece nearest to it, so
//     that no two pieces leave a sample to each other): how far beyond `cover_margin_m`
//     outside the piece it lies;
//   - bulge, per point of the piece's surface (128, evenly spread on the unit sphere and
//     weighted by the area they stand for) that lies on the union's surface (inside no
//     other piece): how far it stands out of the skin beyond `bulge_free_m`, fully
//     weighted, plus a light pull on all of its stand-out. The skin's signed distance
//     (skin_surface.hpp) is sampled on a grid, each grid point when first needed;
//   - reach, for a part of limited reach (a limb bone), per surface point: how far it lies
//     past the span of the part's own samples along their longest axis, beyond `reach_m`,
//     weighted as bulge. Without it a thin shin grows a long tip up inside the thigh (and
//     the thigh down inside the shin): buried at the rest pose, free of cost, it stands out
//     behind the knee by several centimetres as soon as the knee bends, and the cloth
//     draped over it tears (on the sample scene's walk, worst spring 233 % after the frame;
//     with the reach term, 9 %).
// Pieces are refitted in turn (Gauss-Seidel sweeps, each seeing the others' latest shape).
// Then, while the budget allows and the body is not yet within its allowance, the piece
// that fails most (skin it leaves uncovered beyond the tolerance, measured exactly, and
// surface of it standing out beyond `bulge_limit_m`) gets help: a new piece started on its
// largest uncovered patch (a thumb, an ankle between a shin and a foot), or, when it
// mostly stands out, a split of its samples in two (2-means); the mirrored piece on the
// other side gets the same. Last, when the budget is spent and skin is still uncovered,
// the pieces that leave it may stand out further, one centimetre at a time: coverage comes
// first, since a garment must not slip into the body.
// Everything runs in a fixed order, and the parallel parts write only their own outputs:
// the same samples give the same ellipsoids.
#pragma once

#include <cstdint>
#include <vector>

#include "drape/engine/core/math.hpp"
#include "drape/systems/character/skin_surface.hpp"

namespace drape::fitting {

/// An ellipsoid in model space: x = center + axes * diag(radii) * u, |u| = 1.
struct Ellipsoid {
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  ///< Columns: unit axes (a rotation).
    Eigen::Vector3d radii = Eigen::Vector3d::Constant(0.1);
};

/// First-order signed distance from `p` to the surface (exact on it): + outside, - inside.
[[nodiscard]] double signed_distance(const Ellipsoid& e, const Eigen::Vector3d& p) noexcept;

/// Exact distance from a point outside an ellipsoid to it (0 inside); `q` in the
/// ellipsoid's frame (centred, along its axes).
[[nodiscard]] double outside_distance(const Eigen::Vector3d& radii, const Eigen::Vector3d& q) noexcept;
[[nodiscard]] double outside_distance(const Ellipsoid& e, const Eigen::Vector3d& p) noexcept;

/// The fit's weights and margins (tuned on the default avatar and the shared characters).
struct SolverSettings {
    double cover_margin_m = 0.005;   ///< Aim: every sample within this of some ellipsoid.
    double bulge_free_m = 0.016;     ///< Stand-out beyond this is paid for in full ...
    double bulge_weight = 1;         ///< ... with this weight per skin sample's worth of area, relative to cover residuals.
    double tight_weight = 0.01;      ///< A light pull on all stand-out, so that free room is not wasted.
    double face_sample_weight = 0.5; ///< Samples inside faces count this much of a vertex (coverage is judged on vertices).
    double huber_m = 0.03;           ///< Residuals beyond this grow linearly in the cost, not quadratically.
    double coverage_tolerance_m = 0.01;  ///< Splitting: a sample farther than this from all is uncovered ...
    double bulge_limit_m = 0.02;     ///< ... and surface standing out more than this fails.
    double field_spacing_m = 0.01;   ///< Grid of the skin's signed distance.
    double min_radius_m = 0.01;
    int max_pieces = 28;             ///< Budget for new pieces.
    double split_threshold = 0.2;    ///< Stop when no piece fails a fifth of what the body may fail (see fit_pieces) ...
    double target_uncovered = 0.003; ///< ... or when the skin left uncovered (sample-weighted share) ...
    double target_bulging = 0.03;    ///< ... and the share of the surface standing out beyond the limit are both this low.
    int sweeps = 3;                  ///< Gauss-Seidel sweeps before and after the splits.
    int iterations = 30;             ///< Levenberg-Marquardt iterations per fit at most.
    int relax_steps = 3;             ///< Budget spent and skin still uncovered: this many times ...
    double relax_step_m = 0.01;      ///< ... the pieces that leave it may stand out this much further.
};

/// One fitted ellipsoid and the part (bone cluster) it came from.
struct Piece {
    int part = -1;                       ///< Index of the part; pieces split from one part share it.
    std::vector<std::uint32_t> samples;  ///< The samples it answers for (a subset of its part).
    Ellipsoid shape;
    double extra_free_m = 0;             ///< Stand-out it may have beyond SolverSettings::bulge_free_m.
    bool limited_reach = false;          ///< A limb's piece: it may not reach past its own skin along the limb ...
    Eigen::Vector3d reach_axis = Eigen::Vector3d::UnitX();  ///< ... along this axis (its samples' longest) ...
    double reach_lo = 0, reach_hi = 0;   ///< ... beyond the span of its samples on it, m, ...
    double reach_m = 0;                  ///< ... by more than this (PartInfo::reach_m).
};

/// What the solver knows of a part besides its samples.
struct PartInfo {
    int mirror = -1;                     ///< The part on the other side (-1: none): they split together.
    bool may_split = true;               ///< More than one piece allowed (a trunk); false: one piece (a limb).
    bool limited_reach = false;          ///< Its piece may not reach past its own skin along its axis (a limb) ...
    double reach_m = 0.05;               ///< ... by more than this.
};

/// Fits pieces to the skin samples (`skin` the same posed skin, for the signed distance). `part_of` gives each sample's part (-1: none; such
/// samples are covered by whichever piece is nearest); `mirror_of_part` pairs left and
/// right parts (-1: none) so that they split together. Parts with fewer than 4 samples get
/// no piece.
[[nodiscard]] std::vector<Piece> fit_pieces(const SkinSurface& skin, const std::vector<SkinSample>& samples, const std::vector<int>& part_of,
                                            const std::vector<PartInfo>& parts, const SolverSettings& settings);

}  // namespace drape::fitting
