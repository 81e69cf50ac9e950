// The skin cover system (phase render, after the skinning system, before the render
// system): skin a garment covers is drawn inside the body the cloth collides with.
//
// The cloth collides with the character's ellipsoids (method §5), not with its mesh. Where
// the mesh stands out of them (a shirt's hem over the hips, thigh skin between fitted
// ellipsoids) cloth lying on an ellipsoid is drawn behind that skin, and the skin pokes
// through the garment. Game engines hide body skin under clothing for the same reason.
// This system moves, for drawing only, every covered skinned vertex that lies outside all
// of the garment's ellipsoids but within `skin_cover_reach_m` of one onto the surface of the
// nearest (along its centre line) and `skin_cover_inset` inside it. So too a vertex inside
// but less deep than that in every ellipsoid: the cloth is drawn as flat triangles between
// particles that lie on the ellipsoids, which cut a little inside a curved surface, and
// skin just under the surface (where the legs' tight ellipsoids hug it) showed through
// them. Skin farther out is left alone: it is not the body under the cloth (a hand, a bag).
// Only the ellipsoids that do not give count, as inside and as the nearest: cloth may lie
// inside a forearm's or a hand's ellipsoid, within its give (EllipsoidCollider::give_m), but
// never inside the others, so skin drawn in those is under the cloth. Counted, the arms let
// hip skin by a hand hanging at the side (Female_Alternative's) show through her dress.
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

#include "engine/core/math.hpp"
#include "engine/core/registry.hpp"
#include "engine/core/scheduler.hpp"

namespace drape {

/// Covered skin this far or nearer outside the garment's ellipsoids is pulled in.
inline constexpr Real skin_cover_reach_m = Real(0.05);
/// How far inside the surface a pulled vertex is drawn, as a share of its distance from
/// the ellipsoid's centre (5 mm at a 10 cm radius).
inline constexpr Real skin_cover_inset = Real(0.05);

[[nodiscard]] System make_skin_cover_system();

/// Pulls the skin every garment covers inside its body: the system's run, for callers
/// without a scheduler. The meshes must have been skinned at the current pose.
void cover_skin(Registry& registry);

}  // namespace drape
