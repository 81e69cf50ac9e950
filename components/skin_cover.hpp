// The skin a garment covers, as the skin cover system keeps it (systems/skin_cover_system.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace drape {

struct Fabric;  // components/garment.hpp

/// On a garment entity: the vertices of its character's SkinnedMesh that it covers, chosen
/// once from the garment's rest shape (between its hem and its pins, not on an arm, a hand
/// or the head), and drawn pulled inside the body the cloth collides with.
struct SkinCover {
    std::vector<std::uint32_t> vertices;       ///< Indices into the character's SkinnedMesh.
    std::vector<std::uint32_t> faces;          ///< Its triangles (first index into MeshAsset::indices) whose three vertices are covered.
    std::shared_ptr<const Fabric> chosen_for;  ///< The garment's fabric when chosen (a new one: choose again).
    std::size_t mesh_vertices = 0;             ///< The mesh's vertex count when chosen.
    std::uint64_t pulled = 0;                  ///< Vertices pulled in so far, over all frames (a count).
    std::uint64_t pulled_for_faces = 0;        ///< Further pulls of vertices whose faces still stood out, over all frames.
};

}  // namespace drape
