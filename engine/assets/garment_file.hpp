// A garment's mesh as a file holds it: the surface an artist modelled on a character, its
// pattern (UV) coordinates and where it is held (docs/garments.md). Plain data read and
// written through assimp; turning it into cloth is systems/cloth/garment_from_mesh.hpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/image.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// One garment mesh, in the character's model space (metres, +Y up).
struct GarmentMeshAsset {
    std::string name;                     ///< The mesh's name in its file (may be empty).
    Matrix3X positions;                   ///< One column per vertex.
    Matrix2X uvs;                         ///< Pattern coordinates per vertex (u across the grain, v along it); empty: none.
    VectorX pin;                          ///< Per vertex 0..1 (COLOR_0's red): >= 0.5 is held to the body; empty: not painted.
    std::vector<std::uint32_t> indices;   ///< Triangles.
    /// The material's base-colour texture (sRGB, mapped by `uvs` and repeated past [0, 1];
    /// image row 0 at v = 1); empty: none (or no UVs to map it by).
    Image base_color;

    [[nodiscard]] std::size_t vertex_count() const noexcept { return static_cast<std::size_t>(positions.cols()); }
};

/// Reads the mesh named `mesh_name` (or the file's only mesh when empty) from any file assimp
/// reads (glTF 2.0, FBX, OBJ, ...): its triangles, its first UV set, its first colour set's
/// red channel and its material's base-colour texture (glTF's baseColorTexture or a
/// diffuse map: embedded, or a PNG or JPEG file named relative to the garment's), with the
/// file's node transforms applied, in the file's own units (an FBX's UnitScaleFactor is not
/// applied). A mesh an exporter split into parts under one name
/// (one per material: FBX, glTF primitives) is read whole, its parts one after another.
/// Errors name the file and, where it matters, the mesh ("skirt.glb: 2 meshes (Skirt,
/// Belt (2 parts)): name one as skirt.glb:MESH").
[[nodiscard]] Result<GarmentMeshAsset> import_garment_mesh(const std::filesystem::path& path, std::string_view mesh_name = {});

/// Writes `mesh` as glTF 2.0 (".gltf" with its ".bin" beside it, or ".glb"): positions,
/// normals, TEXCOORD_0 from `uvs`, COLOR_0 from `pin` (red = pin, green and blue 0,
/// alpha 1) and `base_color` as the material's baseColorTexture, a PNG embedded in the file.
/// Never overwrites: an existing file is an error.
[[nodiscard]] Result<void> write_garment_mesh(const std::filesystem::path& path, const GarmentMeshAsset& mesh);

/// Splits "FILE:MESH" (the garment's file and the name of one of its meshes) where the part
/// after the last ':' is not a path (a drive or a folder): {"skirt.glb", "Skirt"}, or
/// {"skirt.glb", ""}.
[[nodiscard]] std::pair<std::filesystem::path, std::string> split_garment_reference(std::string_view reference);

}  // namespace drape
