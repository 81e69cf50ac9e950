// The skin cover system (phase render, after the skinning system, before the render
// system): skin a garment covers is drawn inside the body the cloth collides with.
//
// The cloth collides with the character's ellipsoids (method §5), not with its mesh. Where
// the mesh stands out of them (a shirt's hem over the hips, thigh skin between fitted
// ellipsoids) cloth lying on an ellipsoid is drawn behind that skin, and the skin pokes
// through the garment. Game engines hide body skin under clothing for the same reason.
// This system moves, for drawing only, every covered skinned vertex that lies outside all
// of the garment's ellipsoids but within `skin_cover_reach_m` of one onto the surface of the
// nearest (along its centre line) and inside it by `skin_cover_inset` of the way to the
// centre or `skin_cover_min_depth_m`, whichever is deeper (skin_cover_depth). So too a
// vertex inside but less deep than that in every ellipsoid: the cloth is drawn as flat
// triangles between particles that lie on the ellipsoids, which cut a little inside a
// curved surface (about 3 mm into a piece 4 cm thick, between particles 2-3 cm apart), and
// skin just under the surface showed through them. Skin farther out is left alone: it is
// not the body under the cloth (a hand, a bag).
// Only the ellipsoids that do not give count, as inside and as the nearest: cloth may lie
// inside a forearm's or a hand's ellipsoid, within its give (EllipsoidCollider::give_m), but
// never inside the others, so skin drawn in those is under the cloth. Counted, the arms let
// hip skin by a hand hanging at the side (Female_Alternative's) show through her dress. Of
// those, the ones thinner than `skin_cover_min_radius_m` count only where no thicker one
// is within reach: the cloth's triangles cut through a piece 2 cm thick.
// Faces: a face of the skin is drawn flat between its vertices, and on a low-polygon body
// (faces 10-15 cm across) one bridges the crease between two ellipsoids where the cloth
// follows the crease in. While the middle of a covered face or of one of its edges lies
// outside the ellipsoids that hold skin, its vertices are drawn deeper still, a few rounds
// at most. Measured as points of covered faces drawn outside the garment over a walk cycle
// (`SkinCover.*`): Male_Casual's skirt 11.6 % before these rules and 1 point of 10,156
// after, Female_Alternative's dress 0.51 % (thin dark slits of her trousers) and none.
//
// Covered: the vertices whose strongest bone is neither an arm, a hand nor the head (nor a
// bone below them), and that lay between the garment's hem and its highest pin when the
// cover was chosen, the first time the system met the garment (its rest shape on the
// character's pose then). The choice is kept in a SkinCover on the garment entity and made
// again when the garment's fabric or the mesh changes.
//
// Reads Garment, EllipsoidCollider and Skeleton; writes SkinnedMesh and SkinCover. Only a
// world that draws adds it (game/world.cpp), like the skinning system: the simulation never
// sees these positions.
#pragma once

#include "drape/engine/core/math.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"
#include "drape/systems/cloth/garment_solver.hpp"

namespace drape {

/// Covered skin this far or nearer outside the garment's ellipsoids is pulled in.
inline constexpr Real skin_cover_reach_m = Real(0.05);
/// How far inside the surface a pulled vertex is drawn, as a share of its distance from
/// the ellipsoid's centre (5 mm at a 10 cm radius) ...
inline constexpr Real skin_cover_inset = Real(0.05);
/// ... and at least this deep, but never more than half way to the centre: the cloth's flat
/// triangles, 2-3 cm across at a waist, cut about 3 mm inside a piece 4 cm thick, and skin
/// drawn 2 mm inside it showed through Male_Casual's skirt.
inline constexpr Real skin_cover_min_depth_m = Real(0.005);

/// How deep covered skin is drawn in `f`: the radius of the unit sphere it is drawn on
/// (skin_cover_inset of the way in along the centre line, or at least
/// skin_cover_min_depth_m from the surface, whichever is deeper; at least 1/2).
[[nodiscard]] Real skin_cover_depth(const EllipsoidFrame& f) noexcept;

/// Ellipsoids thinner than this (smallest radius) hold covered skin only where no thicker
/// one is within reach: the cloth's flat triangles, 1-3 cm across, cut through a piece 2 cm
/// thick (Male_Casual's and Female_Alternative's thin pieces at the waist and the hip: up
/// to 9.5 mm into one), and skin drawn inside it showed through.
inline constexpr Real skin_cover_min_radius_m = Real(0.02);

/// Whether covered skin may be drawn inside `f`: an active ellipsoid that does not give
/// (cloth may lie inside a forearm's or a hand's, within its give) and, unless `thin_too`,
/// is not thinner than skin_cover_min_radius_m.
[[nodiscard]] bool holds_covered_skin(const EllipsoidFrame& f, bool thin_too = false) noexcept;

[[nodiscard]] System make_skin_cover_system();

/// Pulls the skin every garment covers inside its body: the system's run, for callers
/// without a scheduler. The meshes must have been skinned at the current pose.
void cover_skin(Registry& registry);

}  // namespace drape
