// Lighting (all programs agree): a warm key light from the upper left front, a cool fill
// from the right back, a sky/ground hemisphere ambient; linear RGB in, a soft shoulder
// x(1 + x/4)/(1 + x), then gamma 2 (sqrt) out: the frame buffer is plain RGBA8, and these
// cost little on a software rasteriser (tone_map() in renderer.cpp is the same curve).
#include "drape/engine/render/shaders.hpp"

#include <string>
#include <vector>

namespace drape::render_detail {

#define DRAPE_GLSL_LIGHTS                                                                   \
    "const vec3 key_direction = normalize(vec3(-0.45, 0.80, 0.55));\n"                      \
    "const vec3 key_color = vec3(1.00, 0.95, 0.88) * 0.95;\n"                              \
    "const vec3 fill_direction = normalize(vec3(0.60, 0.30, -0.70));\n"                     \
    "const vec3 fill_color = vec3(0.70, 0.80, 1.00) * 0.30;\n"                             \
    "const vec3 sky_color = vec3(0.36, 0.40, 0.48);\n"                                     \
    "const vec3 ground_color = vec3(0.17, 0.15, 0.13);\n"                                  \
    "vec3 tone(vec3 x) {\n"                                                                 \
    "    x = max(x, vec3(0.0));\n"                                                          \
    "    return sqrt(x * (1.0 + x * 0.25) / (1.0 + x));\n"                                    \
    "}\n"

const char* const lit_vertex_shader = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_view_projection;
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv;
void main() {
    vec4 world = u_model * vec4(a_position, 1.0);
    v_world = world.xyz;
    v_normal = u_normal_matrix * a_normal;
    v_uv = a_uv;
    gl_Position = u_view_projection * world;
}
)";

const char* const lit_fragment_shader = "#version 450 core\n" DRAPE_GLSL_LIGHTS R"(
in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv;
uniform vec4 u_color;        // linear RGB, alpha
uniform int u_textured;      // u_base_color (sRGB, decoded to linear by the sampler) times u_color
uniform sampler2D u_base_color;
uniform vec3 u_eye;
uniform int u_two_sided;     // back faces lit with the flipped normal
uniform float u_specular;
uniform float u_shininess;
uniform float u_rim;
out vec4 o_color;
void main() {
    float len = length(v_normal);
    vec3 n = len > 1e-8 ? v_normal / len : vec3(0.0, 1.0, 0.0);
    if (u_two_sided != 0 && !gl_FrontFacing) n = -n;
    vec3 v = normalize(u_eye - v_world);
    float key = max(dot(n, key_direction), 0.0);
    float fill = max(dot(n, fill_direction), 0.0);
    vec3 ambient = mix(ground_color, sky_color, 0.5 + 0.5 * n.y);
    vec3 h = normalize(key_direction + v);
    float spec = key > 0.0 ? pow(max(dot(n, h), 0.0), u_shininess) * u_specular : 0.0;
    float facing = 1.0 - max(dot(n, v), 0.0);
    float rim = facing * facing * facing * u_rim;
    vec3 albedo = u_color.rgb;
    if (u_textured != 0) albedo *= texture(u_base_color, vec2(v_uv.x, 1.0 - v_uv.y)).rgb;  // row 0 at v = 1
    vec3 color = albedo * (key_color * key + fill_color * fill + ambient) + key_color * spec + sky_color * rim;
    o_color = vec4(tone(color), u_color.a);
}
)";

const char* const ground_vertex_shader = R"(#version 450 core
uniform mat4 u_view_projection;
uniform vec2 u_center;       // ground quad centre (x, z), m
uniform float u_half_size;   // m
out vec2 v_ground;           // world x, z
out float v_depth;           // view depth, m (affine over the plane: interpolates exactly)
void main() {
    const vec2 corners[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));
    v_ground = u_center + corners[gl_VertexID] * u_half_size;
    gl_Position = u_view_projection * vec4(v_ground.x, 0.0, v_ground.y, 1.0);
    v_depth = gl_Position.w;
}
)";

const char* const ground_fragment_shader = "#version 450 core\n" DRAPE_GLSL_LIGHTS R"(
in vec2 v_ground;
in float v_depth;
uniform vec3 u_sky;              // clear colour, linear: the horizon fades into it
uniform vec3 u_albedo;
out vec4 o_color;

// Cheap on a software rasteriser: 1 m checker tiles whose contrast fades with depth
// (before they would alias), and fog on view depth rather than distance.
void main() {
    vec2 cell = floor(v_ground);
    float checker = fract((cell.x + cell.y) * 0.5) * 2.0;          // 0 or 1
    float contrast = 0.14 * clamp(1.0 - v_depth * (1.0 / 18.0), 0.0, 1.0);
    vec3 albedo = u_albedo * (1.0 - contrast * checker);
    vec3 color = albedo * (key_color * key_direction.y + sky_color);
    float fog = clamp((v_depth - 10.0) * (1.0 / 35.0), 0.0, 1.0);
    o_color = vec4(tone(mix(color, u_sky, fog * fog * (3.0 - 2.0 * fog))), 1.0);
}
)";

// A blob costs only the pixels it covers (a loop over blobs in the ground shader would
// cost every ground pixel on a software rasteriser).
const char* const blob_vertex_shader = R"(#version 450 core
uniform mat4 u_view_projection;
uniform vec4 u_blob;             // centre x, centre z, radius m, strength 0..1
out vec2 v_offset;               // -1..1 across the blob
void main() {
    const vec2 corners[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));
    v_offset = corners[gl_VertexID];
    vec2 p = u_blob.xy + v_offset * u_blob.z;
    gl_Position = u_view_projection * vec4(p.x, 0.001, p.y, 1.0);
}
)";

const char* const blob_fragment_shader = R"(#version 450 core
in vec2 v_offset;
uniform vec4 u_blob;
out vec4 o_color;
void main() {
    float occlusion = 1.0 - u_blob.w * (1.0 - smoothstep(0.2, 1.0, length(v_offset)));
    o_color = vec4(vec3(sqrt(occlusion)), 1.0);   // multiplied into gamma-encoded colour
}
)";

const char* const shadow_vertex_shader = R"(#version 450 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view_projection;
uniform mat4 u_shadow;       // projects onto the ground along the key light
void main() { gl_Position = u_view_projection * (u_shadow * vec4(a_position, 1.0)); }
)";

const char* const shadow_fragment_shader = R"(#version 450 core
uniform float u_darkness;
out vec4 o_color;
void main() { o_color = vec4(0.0, 0.0, 0.0, u_darkness); }
)";

const char* const hud_vertex_shader = R"(#version 450 core
layout(location = 0) in vec2 a_pixel;
layout(location = 1) in vec4 a_color;
uniform vec2 u_frame_size;   // px
out vec4 v_color;
void main() {
    v_color = a_color;
    gl_Position = vec4(a_pixel.x / u_frame_size.x * 2.0 - 1.0, 1.0 - a_pixel.y / u_frame_size.y * 2.0, 0.0, 1.0);
}
)";

const char* const hud_fragment_shader = R"(#version 450 core
in vec4 v_color;
out vec4 o_color;
void main() { o_color = v_color; }
)";

namespace {

/// A GL info log as one line: trailing blanks dropped, line breaks turned into "; ".
std::string one_line(std::string log) {
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n' || log.back() == ' ')) log.pop_back();
    std::string out;
    out.reserve(log.size());
    for (char c : log) {
        if (c == '\n') out += "; ";
        else if (c != '\0') out += c;
    }
    return out;
}

Result<GLuint> compile(std::string_view program, GLenum stage, const char* source) {
    const GLuint shader = glCreateShader(stage);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok == GL_TRUE) return shader;
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(length > 0 ? length : 1), '\0');
    glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteShader(shader);
    return fail("shader " + std::string(program) + (stage == GL_VERTEX_SHADER ? " (vertex)" : " (fragment)") +
                ": compile error: " + one_line(std::move(log)));
}

}  // namespace

Result<GLuint> build_program(std::string_view name, const char* vertex_source, const char* fragment_source) {
    auto vertex = compile(name, GL_VERTEX_SHADER, vertex_source);
    if (!vertex) return fail(vertex.error().message);
    auto fragment = compile(name, GL_FRAGMENT_SHADER, fragment_source);
    if (!fragment) {
        glDeleteShader(*vertex);
        return fail(fragment.error().message);
    }
    const GLuint program = glCreateProgram();
    glAttachShader(program, *vertex);
    glAttachShader(program, *fragment);
    glLinkProgram(program);
    glDeleteShader(*vertex);
    glDeleteShader(*fragment);
    GLint ok = GL_FALSE;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (ok == GL_TRUE) return program;
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(length > 0 ? length : 1), '\0');
    glGetProgramInfoLog(program, static_cast<GLsizei>(log.size()), nullptr, log.data());
    glDeleteProgram(program);
    return fail("shader " + std::string(name) + ": link error: " + one_line(std::move(log)));
}

}  // namespace drape::render_detail
