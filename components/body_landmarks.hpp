// Where a character's body is: landmarks found from its skeleton and skin at the rest
// pose (systems/character/body_landmarks.hpp finds them). Garment builders hang a skirt
// from the waist and a dress from under the arms of whatever character it is put on.
//
// Model space at the rest pose, metres, Y up; a "height" is a model-space y.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "drape/engine/core/math.hpp"

namespace drape {

/// A point of the body at the rest pose and the bone that carries it.
struct BodyPoint {
    int bone = -1;                ///< Carries the point when the character moves; -1: none.
    Vec3 rest_m = Vec3::Zero();   ///< Model space, rest pose.
    Vec3 local_m = Vec3::Zero();  ///< The same in the bone's rigid frame at rest.
};

/// A horizontal section of the torso at one height.
struct BodySection {
    BodyPoint center;             ///< Centre of the outline, at the section's height.
    Real half_width_m = 0;        ///< Along BodyLandmarks::left.
    Real half_depth_m = 0;        ///< Along BodyLandmarks::forward.
    Real girth_m = 0;             ///< Perimeter of the convex outline.
};

/// Bones of a limb from the body out (thigh, shin, foot / upper arm, forearm, hand); -1
/// where there is none.
struct LimbChain {
    int root = -1;    ///< Thigh or clavicle/upper arm: the first bone off the trunk.
    int middle = -1;  ///< Shin or forearm.
    int end = -1;     ///< Foot or hand.
};

/// Landmarks of a humanoid body; a component of the character entity.
struct BodyLandmarks {
    Vec3 up = Vec3::UnitY();
    Vec3 forward = Vec3::UnitZ();  ///< Horizontal, across the hip line, model +Z's side.
    Vec3 left = Vec3::UnitX();     ///< up x forward.
    Real floor_m = 0;              ///< Height of the lowest body point.
    Real top_m = 0;                ///< Height of the highest.
    Real height_m = 0;             ///< top - floor: the body only (no base, no root-bound prop).

    int pelvis_bone = -1;          ///< Where the two legs meet the spine.
    std::vector<int> spine;        ///< Bones from the pelvis up to the head, in order.
    int chest_bone = -1;           ///< The spine bone the arms hang from.
    int head_bone = -1;
    LimbChain left_leg, right_leg, left_arm, right_arm;
    std::vector<int> body_bones;   ///< Bones whose skin is body.

    Real crotch_m = 0;             ///< Lowest height where the pelvis's skin crosses the midplane.
    Real underarm_m = 0;           ///< Height under the arms: the higher armpit.
    /// The waist's centre raised to where the arms' skin (by its weights) reaches lowest on
    /// the trunk: at or under the armpits; the built-in dress is held just under it.
    BodyPoint arms_meet_trunk;
    BodySection waist;             ///< Narrowest torso section between crotch and underarm.
    BodySection hips;              ///< Widest trunk section between crotch and waist.
    BodySection chest;             ///< Trunk section reaching farthest forward between waist and underarm.
    BodyPoint left_shoulder, right_shoulder;  ///< The upper arms' heads.
    std::string found_by;          ///< "bone names" or "topology": how the pelvis was found.
    /// How each landmark was found, in the order `drape inspect` prints them: {landmark, how}.
    std::vector<std::pair<std::string, std::string>> how_found;
};

}  // namespace drape
