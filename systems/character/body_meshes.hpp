// Which meshes of a character are its body. Characters come with more than a body: a base
// block they stand on, a weapon or a prop, eyes and hair, and often clothes modelled into
// the file (a skirt, a coat). The ellipsoid fit and the landmarks are made from the body
// only (character_body.hpp); the rest is listed, so `drape inspect` can say what was left
// out and why.
//
// A mesh is left out
//  - as a prop when all its vertices move with one bone that is not on the body's chains
//    (the spine, the leg and arm chains from the trunk out to their tips, and what hangs
//    from the head) and that moves no vertex of another mesh: a base or a prop bound to
//    the root, a weapon on a bone of its own; or when it has no skin and hangs from no
//    bone of the body;
//  - as a modelled garment when its mesh or material is named like one (dress, skirt, coat,
//    gown, robe, cape, cloak, kilt, apron, tunic), or when some of its vertices hang
//    between the thighs (from half way from the hip joints to the knees down to
//    the knees, within a quarter of the hips' spacing of the midline) and move with the
//    trunk, not a thigh (a trouser leg's inside follows its thigh): only cloth hangs there.
//    The mesh carrying most of the head's skin is never a garment.
// Names are a hint for garments only; a prop is found from the rig and the skin.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "drape/components/body_landmarks.hpp"
#include "drape/engine/assets/character_asset.hpp"

namespace drape {

/// A mesh of a character that is not part of its body.
struct LeftOutMesh {
    std::size_t mesh = 0;  ///< Index into CharacterAsset::meshes (and MeshAsset::submeshes).
    bool garment = false;  ///< A modelled garment (else a prop, a base, a weapon).
    std::string why;       ///< One line: what it is bound to, or what its name or shape says.
};

/// The meshes that are not the body, found with the landmarks of a first look at the whole
/// character (its topology: pelvis, spine, limb chains, crotch). A file of one mesh keeps it.
[[nodiscard]] std::vector<LeftOutMesh> find_non_body_meshes(const CharacterAsset& character, const BodyLandmarks& landmarks);

/// A copy of the character holding only the vertices and triangles of the meshes not left
/// out (the same skeleton and clips; `meshes` and the submeshes renumbered), its height
/// that of what is kept.
[[nodiscard]] CharacterAsset body_only(const CharacterAsset& character, const std::vector<LeftOutMesh>& left_out);

}  // namespace drape
