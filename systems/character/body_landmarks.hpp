// Finding a character's body landmarks (components/body_landmarks.hpp) from its skeleton
// and skin at the rest pose (method §2: the garment is fitted to the body it is put on).
//
// Trunk and limbs by topology and geometry, the same for every rig: the pelvis is the bone
// from which two chains hang whose skin reaches the floor (a bone named like hips/pelvis
// is taken when the rig has one); those chains are the legs, the chain from the pelvis
// that reaches highest is the spine up to the head, and the chest is the spine bone from
// which the two chains reaching farthest sideways hang (the arms). Sides come from
// geometry (left = up x forward; forward is across the line through the hip joints, on
// the side of model +Z, the front of glTF and of FBX once imported), never from names.
//
// Definitions (heights are model-space y at rest):
//  - body: the skin of the bones of the pelvis's subtree and of bones hanging from above
//    it that are not its ancestors (feet bound to the root, as in some rigs); the skin of
//    the pelvis's ancestors (a root carrying a base or a prop) is not body.
//  - section at a height: the skin triangles of the given bones cut by the horizontal
//    plane there; the convex outline of the cut gives the centre, half width, half depth
//    and girth.
//  - crotch: where the legs part: the lowest point at which the midplane between the two
//    thighs' joints cuts the skin, within 15 % of the height in front of or behind them and
//    above the knees; else the lowest skin point of the pelvis bone within 2 % of the height
//    of the midplane.
//  - armpit: scanning down from the shoulder, the first height at which the skin's section
//    on that side parts into the trunk's piece and an arm's beyond it (pieces within 0.1 %
//    of the height joined); else the lowest skin point of an arm chain on a triangle it
//    shares with the trunk; where the two are separate pieces (a robot), the shoulder joint
//    less 6 % of the height. underarm = the higher of the two (an arm modelled against
//    the trunk parts from it lower on its side).
//  - arms_meet_trunk: the lowest arm skin on a triangle shared with the trunk (by weight),
//    at or under the armpits; the built-in dress is held under it.
//  - waist: the narrowest trunk section between 30 % and 80 % of the way from crotch to
//    arms_meet_trunk; hips: the widest trunk section between crotch and waist; chest: the
//    section reaching farthest forward between waist and underarm.
//  - shoulders: the first arm chain joint above the armpit and as far out as the trunk's
//    side (the upper arm's head).
#pragma once

#include "drape/components/body_landmarks.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/engine/assets/character_asset.hpp"
#include "drape/engine/core/error.hpp"

namespace drape {

/// Finds the landmarks of an imported character at its rest pose. Not a humanoid (no bone
/// with two legs hanging from it, no spine above it, not two arms): an error naming the
/// file and what is missing, so that a caller can fall back.
[[nodiscard]] Result<BodyLandmarks> find_body_landmarks(const CharacterAsset& character);

/// Where a landmark is on an animated instance: its bone's current pose, then the
/// character's Transform (world space). A point without a bone follows the Transform only.
[[nodiscard]] Vec3 landmark_world(const BodyPoint& point, const Skeleton& pose, const Transform& transform);

}  // namespace drape
