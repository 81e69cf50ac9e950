// Lighting (all programs agree): a warm key light from the upper left front, a cool fill
// from the right back, a sky/ground hemisphere ambient; linear RGB in, a filmic shoulder,
// then sRGB-like gamma 2.2 out (the frame buffer is plain RGBA8).
#include "engine/render/shaders.hpp"

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
    "    vec3 mapped = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);\n"          \
    "    return pow(clamp(mapped, 0.0, 1.0), vec3(1.0 / 2.2));\n"                           \
    "}\n"

const char* const lit_vertex_shader = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_view_projection;
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
out vec3 v_world;
out vec3 v_normal;
void main() {
    vec4 world = u_model * vec4(a_position, 1.0);
    v_world = world.xyz;
    v_normal = u_normal_matrix * a_normal;
    gl_Position = u_view_projection * world;
}
)";

const char* const lit_fragment_shader = "#version 450 core\n" DRAPE_GLSL_LIGHTS R"(
in vec3 v_world;
in vec3 v_normal;
uniform vec4 u_color;        // linear RGB, alpha
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
    float rim = pow(1.0 - max(dot(n, v), 0.0), 3.0) * u_rim;
    vec3 albedo = u_color.rgb;
    vec3 color = albedo * (key_color * key + fill_color * fill + ambient) + key_color * spec + sky_color * rim;
    o_color = vec4(tone(color), u_color.a);
}
)";

const char* const ground_vertex_shader = R"(#version 450 core
uniform mat4 u_view_projection;
uniform vec2 u_center;       // ground quad centre (x, z), m
uniform float u_half_size;   // m
out vec3 v_world;
void main() {
    const vec2 corners[4] = vec2[4](vec2(-1.0, -1.0), vec2(1.0, -1.0), vec2(-1.0, 1.0), vec2(1.0, 1.0));
    vec2 p = u_center + corners[gl_VertexID] * u_half_size;
    v_world = vec3(p.x, 0.0, p.y);
    gl_Position = u_view_projection * vec4(v_world, 1.0);
}
)";

const char* const ground_fragment_shader = "#version 450 core\n" DRAPE_GLSL_LIGHTS R"(
in vec3 v_world;
uniform vec3 u_eye;
uniform vec3 u_sky;              // clear colour, linear: the horizon fades into it
uniform vec3 u_albedo;
uniform int u_blob_count;
uniform vec4 u_blobs[8];         // centre x, centre z, radius m, strength 0..1
out vec4 o_color;

// Box-filtered checker (1 m tiles): no shimmer toward the horizon.
float checker(vec2 p) {
    vec2 w = max(fwidth(p), vec2(1e-4));
    vec2 i = 2.0 * (abs(fract((p - 0.5 * w) * 0.5) - 0.5) - abs(fract((p + 0.5 * w) * 0.5) - 0.5)) / w;
    return 0.5 - 0.5 * i.x * i.y;
}

void main() {
    vec2 p = v_world.xz;
    vec3 albedo = u_albedo * mix(0.86, 1.0, checker(p));
    float occlusion = 1.0;
    for (int i = 0; i < u_blob_count; ++i) {
        float d = length(p - u_blobs[i].xy) / u_blobs[i].z;
        occlusion *= 1.0 - u_blobs[i].w * (1.0 - smoothstep(0.2, 1.0, d));
    }
    vec3 color = albedo * (key_color * key_direction.y + sky_color) * occlusion;
    float distance = length(u_eye - v_world);
    float fog = smoothstep(12.0, 45.0, distance);
    o_color = vec4(tone(mix(color, u_sky, fog)), 1.0);
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

namespace {

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
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    return fail("shader " + std::string(program) + (stage == GL_VERTEX_SHADER ? " (vertex)" : " (fragment)") +
                ": compile error: " + log);
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
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    return fail("shader " + std::string(name) + ": link error: " + log);
}

}  // namespace drape::render_detail
