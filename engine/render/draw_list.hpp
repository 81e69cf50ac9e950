// What the renderer draws in one frame: triangle meshes with their colours and how they
// take the light, and translucent debug ellipsoids. The render backend knows nothing else
// of the scene: a caller (systems/render_system.cpp) fills a DrawList from its own data
// each frame and hands it to Renderer::draw().
//
// Meshes point at the caller's positions, normals and indices instead of copying them;
// the data must stay alive and unchanged until draw() returns.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drape/engine/core/image.hpp"
#include "drape/engine/core/math.hpp"

namespace drape {

/// Identifies a mesh across frames: the renderer keeps its GPU buffers under this key
/// (created when it first appears or its vertex count or triangle list changes, freed
/// when a frame no longer has it), so a steady scene allocates nothing on the GPU per
/// frame. Unique within a list.
struct DrawKey {
    std::uint64_t object = 0;  ///< The caller's id of what is drawn (e.g. an entity).
    std::uint32_t part = 0;    ///< Which of the object's meshes.
    friend bool operator==(const DrawKey&, const DrawKey&) = default;
};

/// A range of a mesh's triangle indices drawn in its own colour (a submesh).
struct DrawRange {
    std::uint32_t first_index = 0;          ///< Into MeshDraw::triangles.
    std::uint32_t index_count = 0;
    Vec3 color = Vec3(0.8f, 0.7f, 0.6f);    ///< Linear RGB; clamped to [0, 1].
    std::string_view name;                  ///< Names the range in error messages.
};

/// How a surface takes the light: the lit shader's material.
struct SurfaceLook {
    Real specular = Real(0.18);  ///< Strength of the key light's highlight.
    Real shininess = 24;         ///< Its Phong exponent.
    Real rim = Real(0.25);       ///< Strength of the rim light.
    bool two_sided = false;      ///< Back faces are lit with the flipped normal (thin cloth seen from behind).
};

/// One triangle mesh in world space.
struct MeshDraw {
    DrawKey key;
    std::string name;                          ///< Names the mesh in error messages ("garment of entity 3").
    const Matrix3X* positions = nullptr;       ///< World, m. Null or empty: nothing to draw.
    const Matrix3X* normals = nullptr;         ///< World, unit, one per position; null (or another count):
                                               ///< area-weighted normals computed from the triangles.
    std::span<const std::uint32_t> triangles;  ///< Three indices per triangle, counter-clockwise = front.
    Vec3 color = Vec3(0.8f, 0.7f, 0.6f);       ///< Linear RGB of the whole mesh when `ranges` is empty; clamped to [0, 1].
    std::vector<DrawRange> ranges;             ///< Parts of `triangles` in their own colours (only these are lit).
    /// A base-colour texture (sRGB, repeated; row 0 at v = 1), its colour multiplying `color`,
    /// mapped by `uvs` (one per position). Either null, or `uvs` of another count: untextured.
    /// The renderer keeps the texture on the GPU while the same image is listed under the key.
    const Image* texture = nullptr;
    const Matrix2X* uvs = nullptr;
    SurfaceLook look;
    bool casts_shadow = true;                  ///< Flattened onto the ground along the key light.
    bool contact_shadow = false;               ///< A soft blob on the ground under its lowest quarter (a body's feet).
};

/// Everything drawn in one frame, besides the ground and sky.
struct DrawList {
    std::vector<MeshDraw> meshes;      ///< Drawn in this order.
    /// Translucent debug ellipsoids, unit sphere -> world; drawn when the renderer shows
    /// ellipsoids (Renderer::set_show_ellipsoids).
    std::vector<Affine3> ellipsoids;
    Vec4 ellipsoid_color = Vec4(0.15f, 0.75f, 0.95f, 0.32f);  ///< Linear RGB and opacity.
    /// Bad data the caller found and left out of the list, one line each naming it; the
    /// renderer reports the first as the frame's error.
    std::vector<std::string> problems;

    void clear() {
        meshes.clear();
        ellipsoids.clear();
        problems.clear();
    }
};

}  // namespace drape
