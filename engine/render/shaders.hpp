// GLSL 4.50 sources of the scene pass and a checked program builder. Internal.
#pragma once

#include <string_view>

#include "drape/engine/core/error.hpp"
#include "drape/engine/render/gl.hpp"

namespace drape::render_detail {

/// Lit surfaces: meshes (two-sided for cloth) and ellipsoids. Key + fill + hemisphere ambient.
extern const char* const lit_vertex_shader;
extern const char* const lit_fragment_shader;
/// The ground plane (drawn from gl_VertexID, no buffer) with blob contact shadows and fog.
extern const char* const ground_vertex_shader;
extern const char* const ground_fragment_shader;
/// Soft contact shadows: a ground quad per blob, multiplied into the frame.
extern const char* const blob_vertex_shader;
extern const char* const blob_fragment_shader;
/// Planar projected shadows onto the ground.
extern const char* const shadow_vertex_shader;
extern const char* const shadow_fragment_shader;
/// The heads-up overlay: 2D triangles in pixels (top-left origin) with a colour each.
extern const char* const hud_vertex_shader;
extern const char* const hud_fragment_shader;

/// Compiles and links a program; the error names the program, the stage and the GL log.
[[nodiscard]] Result<GLuint> build_program(std::string_view name, const char* vertex_source,
                                           const char* fragment_source);

}  // namespace drape::render_detail
