// The renderer: context, frame buffers and the scene pass over a DrawList.
//
// Frame (Impl::draw, one function per step): upload the list's meshes and find their
// contact shadows; free the buffers of meshes no longer listed; bind the (multisampled)
// draw framebuffer, clear; ground; blob contact shadows; planar shadows of the casters
// along the key light (stencil: each pixel darkened once); the lit meshes in list order;
// translucent ellipsoids; resolve into a single-sample framebuffer that read_pixels()
// reads and present() blits to the window.
//
// GPU buffers are kept per DrawKey and updated with glNamedBufferSubData each frame; they
// are created when a key first appears (or its vertex count or triangle list changes) and
// freed when a frame no longer lists it, so a steady scene allocates nothing per frame.
#include "drape/engine/render/renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "drape/engine/core/mesh_normals.hpp"
#include "drape/engine/render/egl_context.hpp"
#include "drape/engine/render/gl.hpp"
#include "drape/engine/render/hud_layout.hpp"
#include "drape/engine/render/shaders.hpp"
#include "drape/engine/render/x11_window.hpp"

namespace drape {

using render_detail::EglContext;
using render_detail::X11Window;

Result<void> validate(const RenderSettings& s) {
    if (s.width < 16 || s.width > 8192) return fail("render settings: width: " + std::to_string(s.width) + " is outside 16..8192 px");
    if (s.height < 16 || s.height > 8192) return fail("render settings: height: " + std::to_string(s.height) + " is outside 16..8192 px");
    if (s.msaa_samples < -1 || s.msaa_samples > 16)
        return fail("render settings: msaa_samples: " + std::to_string(s.msaa_samples) + " is outside -1 (automatic)..16");
    if (!s.clear_color.allFinite() || (s.clear_color.array() < 0).any() || (s.clear_color.array() > 1).any())
        return fail("render settings: clear_color: each channel must be in 0..1");
    return {};
}

namespace {

constexpr int max_blobs = 8;

/// The shaders' tone curve (shaders.cpp), for colours the CPU writes directly (the clear).
Vec3 tone_map(const Vec3& linear) {
    const Eigen::Array3f x = linear.array().max(Real(0));
    return (x * (1 + x * Real(0.25)) / (1 + x)).sqrt().matrix();
}

struct DrawKeyHash {
    std::size_t operator()(const DrawKey& key) const noexcept {
        return std::hash<std::uint64_t>{}(key.object * 0x9E3779B97F4A7C15ull ^ key.part);
    }
};

Vec3 clamp01(const Vec3& color) { return color.cwiseMax(Vec3::Zero()).cwiseMin(Vec3::Ones()); }

Mat3 normal_matrix(const Affine3& m) { return m.linear().inverse().transpose(); }

/// Flattens points onto y = lift along the (towards-the-light) direction l.
Mat4 planar_shadow_matrix(const Vec3& l, Real lift) {
    Mat4 m = Mat4::Identity();
    m(0, 1) = -l.x() / l.y();
    m(0, 3) = l.x() / l.y() * lift;
    m(1, 1) = 0;
    m(1, 3) = lift;
    m(2, 1) = -l.z() / l.y();
    m(2, 3) = l.z() / l.y() * lift;
    return m;
}

/// Vertex array with positions (location 0) and normals (location 1), each a tightly
/// packed float3 buffer, an index buffer, and for a textured mesh its UVs (location 2,
/// float2, uploaded once). Buffer sizes are fixed at creation.
struct MeshBuffers {
    GLuint vao = 0, positions = 0, normals = 0, indices = 0, uvs = 0;
    GLsizei vertex_count = 0, index_count = 0;

    void create(GLsizei vertices, const std::uint32_t* index_data, GLsizei indices_count) {
        vertex_count = vertices;
        index_count = indices_count;
        const GLsizeiptr bytes = GLsizeiptr(vertices) * 3 * GLsizeiptr(sizeof(float));
        glCreateBuffers(1, &positions);
        glNamedBufferData(positions, bytes, nullptr, GL_DYNAMIC_DRAW);
        glCreateBuffers(1, &normals);
        glNamedBufferData(normals, bytes, nullptr, GL_DYNAMIC_DRAW);
        glCreateBuffers(1, &indices);
        glNamedBufferData(indices, GLsizeiptr(indices_count) * GLsizeiptr(sizeof(std::uint32_t)), index_data, GL_STATIC_DRAW);
        glCreateVertexArrays(1, &vao);
        glVertexArrayVertexBuffer(vao, 0, positions, 0, 3 * sizeof(float));
        glVertexArrayVertexBuffer(vao, 1, normals, 0, 3 * sizeof(float));
        for (GLuint i = 0; i < 2; ++i) {
            glEnableVertexArrayAttrib(vao, i);
            glVertexArrayAttribFormat(vao, i, 3, GL_FLOAT, GL_FALSE, 0);
            glVertexArrayAttribBinding(vao, i, i);
        }
        glVertexArrayElementBuffer(vao, indices);
    }
    void set_uvs(const Matrix2X& uv) {
        if (uvs == 0) {
            glCreateBuffers(1, &uvs);
            glNamedBufferData(uvs, GLsizeiptr(vertex_count) * 2 * GLsizeiptr(sizeof(float)), nullptr, GL_STATIC_DRAW);
            glVertexArrayVertexBuffer(vao, 2, uvs, 0, 2 * sizeof(float));
            glEnableVertexArrayAttrib(vao, 2);
            glVertexArrayAttribFormat(vao, 2, 2, GL_FLOAT, GL_FALSE, 0);
            glVertexArrayAttribBinding(vao, 2, 2);
        }
        glNamedBufferSubData(uvs, 0, GLsizeiptr(vertex_count) * 2 * GLsizeiptr(sizeof(float)), uv.data());
    }
    void upload(const Matrix3X& p, const Matrix3X& n) const {
        const GLsizeiptr bytes = GLsizeiptr(vertex_count) * 3 * GLsizeiptr(sizeof(float));
        glNamedBufferSubData(positions, 0, bytes, p.data());
        glNamedBufferSubData(normals, 0, bytes, n.data());
    }
    void destroy() {
        if (vao != 0) glDeleteVertexArrays(1, &vao);
        const GLuint buffers[4] = {positions, normals, indices, uvs};
        glDeleteBuffers(4, buffers);
        *this = {};
    }
};

/// First index that is out of range, or -1.
long long first_bad_index(std::span<const std::uint32_t> indices, std::size_t vertex_count) {
    for (std::size_t i = 0; i < indices.size(); ++i)
        if (indices[i] >= vertex_count) return static_cast<long long>(i);
    return -1;
}

}  // namespace

struct Renderer::Impl {
    RenderSettings settings;
    RendererInfo info;
    Camera camera;
    bool show_ellipsoids = false;

    std::unique_ptr<X11Window> window;     // destroyed after the context (declared first)
    std::unique_ptr<EglContext> context;

    GLuint draw_fbo = 0, draw_color = 0, draw_depth = 0;
    GLuint resolve_fbo = 0, resolve_color = 0;
    GLuint empty_vao = 0;
    GLuint lit = 0, ground = 0, blob = 0, shadow = 0, hud = 0;
    GLint hud_frame_size = -1;
    GLuint hud_vao = 0, hud_buffer = 0;
    GLsizeiptr hud_buffer_bytes = 0;
    std::vector<render_detail::HudVertex> hud_vertices;  // scratch
    struct {
        GLint view_projection, model, normal_matrix, color, eye, two_sided, specular, shininess, rim, textured, base_color;
    } lit_u{};
    struct {
        GLint view_projection, center, half_size, sky, albedo;
    } ground_u{};
    struct {
        GLint view_projection, blob;
    } blob_u{};
    struct {
        GLint view_projection, shadow, darkness;
    } shadow_u{};
    MeshBuffers sphere;

    /// The GPU side of one DrawKey, kept between frames.
    struct MeshEntry {
        MeshBuffers buffers;
        const std::uint32_t* triangles = nullptr;  // the index data the buffers hold; null: nothing valid
        std::size_t index_count = 0;
        Matrix3X computed_normals;                 // when the mesh comes without normals
        const Matrix2X* uvs = nullptr;             // the UVs the buffers hold; null: none
        GLuint texture = 0;                        // the base-colour texture on the GPU; 0: none
        const Image* texture_image = nullptr;      // the image it was made from
        std::uint64_t seen = 0;                    // the last frame that listed it
    };
    /// A listed mesh whose buffers are valid and uploaded this frame.
    struct ReadyMesh {
        const MeshDraw* mesh;
        const MeshEntry* entry;
    };
    /// The camera and the key light of a frame.
    struct FrameView {
        Mat4 view_projection;
        Vec3 eye;
        Vec3 key_direction;  // towards the light, as in the shaders
    };
    std::unordered_map<DrawKey, MeshEntry, DrawKeyHash> meshes;
    std::vector<ReadyMesh> ready;                   // this frame's drawable meshes, in list order
    std::array<Eigen::Vector4f, max_blobs> blobs{}; // this frame's contact shadows: centre x, z, radius, strength
    int blob_count = 0;
    std::vector<DrawKey> stale;         // scratch
    std::vector<std::uint8_t> readback; // scratch, bottom row first
    std::uint64_t frame = 0;
    std::string frame_error;            // first problem of the last draw
    bool drawn = false;

    ~Impl() {
        if (!context || !context->make_current()) return;
        for (auto& [key, entry] : meshes) destroy(entry);
        sphere.destroy();
        glDeleteProgram(lit);
        glDeleteProgram(ground);
        glDeleteProgram(shadow);
        glDeleteProgram(blob);
        glDeleteProgram(hud);
        glDeleteBuffers(1, &hud_buffer);
        glDeleteVertexArrays(1, &hud_vao);
        glDeleteVertexArrays(1, &empty_vao);
        const GLuint fbos[2] = {draw_fbo, resolve_fbo};
        glDeleteFramebuffers(2, fbos);
        const GLuint rbs[3] = {draw_color, draw_depth, resolve_color};
        glDeleteRenderbuffers(3, rbs);
    }

    static void destroy(MeshEntry& entry) {
        entry.buffers.destroy();
        if (entry.texture != 0) glDeleteTextures(1, &entry.texture);
        entry.texture = 0;
        entry.texture_image = nullptr;
        entry.uvs = nullptr;
    }
    void prepare_texture(const MeshDraw& mesh, MeshEntry& entry);

    void note(std::string message) {
        if (frame_error.empty()) frame_error = std::move(message);
    }

    Result<void> create_framebuffers();
    Result<void> create_programs();
    void create_sphere();

    void draw(const DrawList& list);
    // The steps of a frame, in order.
    void upload_meshes(const DrawList& list);
    [[nodiscard]] bool prepare_buffers(const MeshDraw& mesh, MeshEntry& entry);
    void find_contact_blobs();
    void free_unlisted_buffers();
    void clear_frame();
    void draw_ground(const FrameView& view);
    void draw_contact_blobs(const FrameView& view);
    void draw_planar_shadows(const FrameView& view);
    void draw_lit_meshes(const FrameView& view);
    void draw_ellipsoids(const FrameView& view, const DrawList& list);
    void resolve();
    void draw_hud(const HudOverlay& overlay);
    GLuint read_fbo() const { return resolve_fbo != 0 ? resolve_fbo : draw_fbo; }
};

Result<void> Renderer::Impl::create_framebuffers() {
    GLint max_samples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    int requested = settings.msaa_samples;
    if (requested < 0) {
        const std::string& name = info.gl_renderer;
        const bool software = name.find("llvmpipe") != std::string::npos || name.find("softpipe") != std::string::npos ||
                              name.find("swrast") != std::string::npos;
        requested = software ? 0 : 4;
    }
    int samples = requested <= 1 ? 0 : std::min(requested, max_samples);
    if (samples <= 1) samples = 0;
    info.msaa_samples = samples;
    const GLsizei w = settings.width, h = settings.height;

    glCreateRenderbuffers(1, &draw_color);
    glCreateRenderbuffers(1, &draw_depth);
    glNamedRenderbufferStorageMultisample(draw_color, samples, GL_RGBA8, w, h);
    glNamedRenderbufferStorageMultisample(draw_depth, samples, GL_DEPTH24_STENCIL8, w, h);
    glCreateFramebuffers(1, &draw_fbo);
    glNamedFramebufferRenderbuffer(draw_fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, draw_color);
    glNamedFramebufferRenderbuffer(draw_fbo, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, draw_depth);
    if (glCheckNamedFramebufferStatus(draw_fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return fail("OpenGL: the " + std::to_string(w) + "x" + std::to_string(h) + " draw framebuffer (" +
                    std::to_string(samples) + " samples) is incomplete");
    if (samples > 0) {
        glCreateRenderbuffers(1, &resolve_color);
        glNamedRenderbufferStorage(resolve_color, GL_RGBA8, w, h);
        glCreateFramebuffers(1, &resolve_fbo);
        glNamedFramebufferRenderbuffer(resolve_fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_color);
        if (glCheckNamedFramebufferStatus(resolve_fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            return fail("OpenGL: the resolve framebuffer is incomplete");
    }
    if (const GLenum error = glGetError(); error != GL_NO_ERROR)
        return fail("OpenGL: cannot allocate " + std::to_string(w) + "x" + std::to_string(h) +
                    " frame buffers (GL error 0x" + std::to_string(error) + ")");
    return {};
}

Result<void> Renderer::Impl::create_programs() {
    auto l = render_detail::build_program("lit", render_detail::lit_vertex_shader, render_detail::lit_fragment_shader);
    if (!l) return fail(l.error().message);
    lit = *l;
    auto g = render_detail::build_program("ground", render_detail::ground_vertex_shader,
                                          render_detail::ground_fragment_shader);
    if (!g) return fail(g.error().message);
    ground = *g;
    auto s = render_detail::build_program("shadow", render_detail::shadow_vertex_shader,
                                          render_detail::shadow_fragment_shader);
    if (!s) return fail(s.error().message);
    shadow = *s;
    auto b = render_detail::build_program("blob", render_detail::blob_vertex_shader, render_detail::blob_fragment_shader);
    if (!b) return fail(b.error().message);
    blob = *b;
    auto h = render_detail::build_program("hud", render_detail::hud_vertex_shader, render_detail::hud_fragment_shader);
    if (!h) return fail(h.error().message);
    hud = *h;
    auto at = [](GLuint p, const char* n) { return glGetUniformLocation(p, n); };
    hud_frame_size = at(hud, "u_frame_size");
    glCreateVertexArrays(1, &hud_vao);
    glCreateBuffers(1, &hud_buffer);
    glVertexArrayVertexBuffer(hud_vao, 0, hud_buffer, 0, sizeof(render_detail::HudVertex));
    glEnableVertexArrayAttrib(hud_vao, 0);
    glVertexArrayAttribFormat(hud_vao, 0, 2, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(hud_vao, 0, 0);
    glEnableVertexArrayAttrib(hud_vao, 1);
    glVertexArrayAttribFormat(hud_vao, 1, 4, GL_FLOAT, GL_FALSE, 2 * sizeof(float));
    glVertexArrayAttribBinding(hud_vao, 1, 0);
    lit_u = {at(lit, "u_view_projection"), at(lit, "u_model"), at(lit, "u_normal_matrix"), at(lit, "u_color"),
             at(lit, "u_eye"), at(lit, "u_two_sided"), at(lit, "u_specular"), at(lit, "u_shininess"), at(lit, "u_rim"),
             at(lit, "u_textured"), at(lit, "u_base_color")};
    ground_u = {at(ground, "u_view_projection"), at(ground, "u_center"), at(ground, "u_half_size"),
                at(ground, "u_sky"), at(ground, "u_albedo")};
    blob_u = {at(blob, "u_view_projection"), at(blob, "u_blob")};
    shadow_u = {at(shadow, "u_view_projection"), at(shadow, "u_shadow"), at(shadow, "u_darkness")};
    glCreateVertexArrays(1, &empty_vao);
    return {};
}

void Renderer::Impl::create_sphere() {
    constexpr int slices = 32, stacks = 16;
    Matrix3X p(3, (slices + 1) * (stacks + 1));
    std::vector<std::uint32_t> indices;
    indices.reserve(slices * stacks * 6);
    for (int i = 0; i <= stacks; ++i) {
        const Real theta = Real(std::numbers::pi) * Real(i) / stacks;
        for (int j = 0; j <= slices; ++j) {
            const Real phi = 2 * Real(std::numbers::pi) * Real(j) / slices;
            p.col(i * (slices + 1) + j) = Vec3(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
        }
    }
    for (int i = 0; i < stacks; ++i)
        for (int j = 0; j < slices; ++j) {
            const std::uint32_t a = std::uint32_t(i * (slices + 1) + j), b = a + slices + 1;
            indices.insert(indices.end(), {a, b, a + 1, a + 1, b, b + 1});
        }
    sphere.create(GLsizei(p.cols()), indices.data(), GLsizei(indices.size()));
    sphere.upload(p, p);  // unit sphere: normal = position
}

void Renderer::Impl::draw(const DrawList& list) {
    ++frame;
    frame_error.clear();
    if (!list.problems.empty()) note(list.problems.front());
    const FrameView view{camera.projection(Real(settings.width) / Real(settings.height)) * camera.view(), camera.eye(),
                         Vec3(-0.45f, 0.80f, 0.55f).normalized()};
    upload_meshes(list);
    find_contact_blobs();
    free_unlisted_buffers();
    clear_frame();
    draw_ground(view);
    draw_contact_blobs(view);
    draw_planar_shadows(view);
    draw_lit_meshes(view);
    draw_ellipsoids(view, list);
    resolve();
    drawn = true;
}

// Uploads positions and normals of every listed mesh whose data is valid; those become
// this frame's `ready` meshes. A bad mesh is left out and noted.
void Renderer::Impl::upload_meshes(const DrawList& list) {
    ready.clear();
    for (const MeshDraw& mesh : list.meshes) {
        if (mesh.positions == nullptr || mesh.positions->cols() == 0 || mesh.triangles.empty()) continue;
        MeshEntry& entry = meshes[mesh.key];
        entry.seen = frame;
        if (!prepare_buffers(mesh, entry)) continue;
        const Matrix3X& positions = *mesh.positions;
        if (mesh.normals != nullptr && mesh.normals->cols() == positions.cols()) {
            entry.buffers.upload(positions, *mesh.normals);
        } else {
            vertex_normals(positions, mesh.triangles, entry.computed_normals);
            entry.buffers.upload(positions, entry.computed_normals);
        }
        prepare_texture(mesh, entry);
        ready.push_back({&mesh, &entry});
    }
}

// (Re)creates the buffers of a mesh when its vertex count or triangle list changed; the
// index check runs then, not every frame. Ranges are checked every frame (they are few).
bool Renderer::Impl::prepare_buffers(const MeshDraw& mesh, MeshEntry& entry) {
    const Eigen::Index vertices = mesh.positions->cols();
    if (entry.triangles != mesh.triangles.data() || entry.index_count != mesh.triangles.size() ||
        entry.buffers.vertex_count != vertices) {
        destroy(entry);
        entry.triangles = nullptr;
        entry.index_count = 0;
        if (mesh.triangles.size() % 3 != 0) {
            note(mesh.name + ": triangle index count " + std::to_string(mesh.triangles.size()) + " is not a multiple of 3");
            return false;
        }
        if (auto bad = first_bad_index(mesh.triangles, std::size_t(vertices)); bad >= 0) {
            note(mesh.name + ": triangles[" + std::to_string(bad) + "] = " + std::to_string(mesh.triangles[std::size_t(bad)]) +
                 " is past its " + std::to_string(vertices) + " vertices");
            return false;
        }
        entry.buffers.create(GLsizei(vertices), mesh.triangles.data(), GLsizei(mesh.triangles.size()));
        entry.triangles = mesh.triangles.data();
        entry.index_count = mesh.triangles.size();
    }
    for (const DrawRange& range : mesh.ranges)
        if (std::uint64_t(range.first_index) + range.index_count > mesh.triangles.size()) {
            note(mesh.name + ": range \"" + std::string(range.name) + "\" reaches past the triangle list");
            return false;
        }
    return true;
}

// A textured mesh's UVs (uploaded when they are new to the buffers) and its texture (made
// when the image is new to the key: sRGB, mipmapped, repeated). A texture of a bad size, or
// UVs of another count, draw the mesh untextured and say so.
void Renderer::Impl::prepare_texture(const MeshDraw& mesh, MeshEntry& entry) {
    if (mesh.texture == nullptr || mesh.uvs == nullptr) return;
    if (mesh.uvs->cols() != mesh.positions->cols()) {
        note(mesh.name + ": " + std::to_string(mesh.uvs->cols()) + " UVs for " + std::to_string(mesh.positions->cols()) + " vertices (drawn untextured)");
        return;
    }
    if (mesh.texture->empty() || mesh.texture->rgba.size() != std::size_t(mesh.texture->width) * std::size_t(mesh.texture->height) * 4) {
        note(mesh.name + ": its texture's pixels do not match its size " + std::to_string(mesh.texture->width) + "x" +
             std::to_string(mesh.texture->height) + " (drawn untextured)");
        return;
    }
    if (entry.uvs != mesh.uvs) {
        entry.buffers.set_uvs(*mesh.uvs);
        entry.uvs = mesh.uvs;
    }
    if (entry.texture_image == mesh.texture && entry.texture != 0) return;
    if (entry.texture != 0) glDeleteTextures(1, &entry.texture);
    const Image& image = *mesh.texture;
    int levels = 1;
    while ((std::max(image.width, image.height) >> levels) > 0) ++levels;
    glCreateTextures(GL_TEXTURE_2D, 1, &entry.texture);
    glTextureStorage2D(entry.texture, levels, GL_SRGB8_ALPHA8, image.width, image.height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(entry.texture, 0, 0, 0, image.width, image.height, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba.data());
    glGenerateTextureMipmap(entry.texture);
    glTextureParameteri(entry.texture, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTextureParameteri(entry.texture, GL_TEXTURE_WRAP_T, GL_REPEAT);
    glTextureParameteri(entry.texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTextureParameteri(entry.texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    entry.texture_image = mesh.texture;
}

// Contact shadow: a soft blob under the footprint of a body's lowest quarter (the feet and
// legs, not the swinging arms), fading as the body leaves the ground.
void Renderer::Impl::find_contact_blobs() {
    blob_count = 0;
    for (const ReadyMesh& r : ready) {
        if (!r.mesh->contact_shadow || blob_count >= max_blobs) continue;
        const Matrix3X& positions = *r.mesh->positions;
        const auto bounds = finite_bounds(positions);
        if (!bounds) continue;
        const Vec3& lo = bounds->lo;
        const Vec3& hi = bounds->hi;
        const Real feet_top = lo.y() + Real(0.25) * (hi.y() - lo.y());
        Eigen::Vector2f feet_lo(hi.x(), hi.z()), feet_hi(lo.x(), lo.z());
        for (Eigen::Index i = 0; i < positions.cols(); ++i)
            if (positions(1, i) <= feet_top && positions.col(i).allFinite()) {
                const Eigen::Vector2f q(positions(0, i), positions(2, i));
                feet_lo = feet_lo.cwiseMin(q);
                feet_hi = feet_hi.cwiseMax(q);
            }
        const Eigen::Vector2f extent = feet_hi - feet_lo;
        const Real radius = std::clamp(Real(0.9) * extent.maxCoeff(), Real(0.2), Real(1.0));
        const Real lift = std::clamp(lo.y() / Real(0.5), Real(0), Real(1));
        const Eigen::Vector2f centre = Real(0.5) * (feet_lo + feet_hi);
        blobs[std::size_t(blob_count++)] = Eigen::Vector4f(centre.x(), centre.y(), radius, Real(0.8) * (1 - lift));
    }
}

void Renderer::Impl::free_unlisted_buffers() {
    stale.clear();
    for (auto& [key, entry] : meshes)
        if (entry.seen != frame) stale.push_back(key);
    for (const DrawKey& key : stale) {
        destroy(meshes[key]);
        meshes.erase(key);
    }
}

void Renderer::Impl::clear_frame() {
    glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo);
    glViewport(0, 0, settings.width, settings.height);
    const Vec3 clear = tone_map(settings.clear_color);
    glClearColor(clear.x(), clear.y(), clear.z(), 1);
    glClearStencil(0);
    glDepthMask(GL_TRUE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    if (info.msaa_samples > 0) glEnable(GL_MULTISAMPLE);
}

void Renderer::Impl::draw_ground(const FrameView& view) {
    glUseProgram(ground);
    glUniformMatrix4fv(ground_u.view_projection, 1, GL_FALSE, view.view_projection.data());
    glUniform2f(ground_u.center, std::round(camera.target.x()), std::round(camera.target.z()));
    glUniform1f(ground_u.half_size, 80.0f);
    glUniform3fv(ground_u.sky, 1, settings.clear_color.data());
    glUniform3f(ground_u.albedo, 0.38f, 0.37f, 0.35f);
    glBindVertexArray(empty_vao);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
}

// The blobs are multiplied into the ground (the empty vertex array is still bound).
void Renderer::Impl::draw_contact_blobs(const FrameView& view) {
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_DST_COLOR, GL_ZERO);
    glUseProgram(blob);
    glUniformMatrix4fv(blob_u.view_projection, 1, GL_FALSE, view.view_projection.data());
    for (int i = 0; i < blob_count; ++i) {
        glUniform4fv(blob_u.blob, 1, blobs[std::size_t(i)].data());
        glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    }
}

// Every caster flattened onto the ground, each pixel darkened once (stencil). Runs with
// depth writes off and blending on, as the blobs left them.
void Renderer::Impl::draw_planar_shadows(const FrameView& view) {
    glUseProgram(shadow);
    glUniformMatrix4fv(shadow_u.view_projection, 1, GL_FALSE, view.view_projection.data());
    const Mat4 flatten = planar_shadow_matrix(view.key_direction, Real(0.002));
    glUniformMatrix4fv(shadow_u.shadow, 1, GL_FALSE, flatten.data());
    glUniform1f(shadow_u.darkness, 0.38f);
    glEnable(GL_STENCIL_TEST);
    glStencilFunc(GL_EQUAL, 0, 0xFF);
    glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    for (const ReadyMesh& r : ready) {
        if (!r.mesh->casts_shadow) continue;
        glBindVertexArray(r.entry->buffers.vao);
        glDrawElements(GL_TRIANGLES, r.entry->buffers.index_count, GL_UNSIGNED_INT, nullptr);
    }
    glDisable(GL_STENCIL_TEST);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
}

void Renderer::Impl::draw_lit_meshes(const FrameView& view) {
    glUseProgram(lit);
    glUniformMatrix4fv(lit_u.view_projection, 1, GL_FALSE, view.view_projection.data());
    const Mat4 identity = Mat4::Identity();
    const Mat3 identity3 = Mat3::Identity();
    glUniformMatrix4fv(lit_u.model, 1, GL_FALSE, identity.data());
    glUniformMatrix3fv(lit_u.normal_matrix, 1, GL_FALSE, identity3.data());
    glUniform3fv(lit_u.eye, 1, view.eye.data());
    glUniform1i(lit_u.base_color, 0);  // texture unit 0
    for (const ReadyMesh& r : ready) {
        const MeshDraw& mesh = *r.mesh;
        glUniform1i(lit_u.two_sided, mesh.look.two_sided ? 1 : 0);
        glUniform1f(lit_u.specular, mesh.look.specular);
        glUniform1f(lit_u.shininess, mesh.look.shininess);
        glUniform1f(lit_u.rim, mesh.look.rim);
        const bool textured = r.entry->texture != 0 && r.entry->texture_image == mesh.texture && mesh.uvs == r.entry->uvs;
        glUniform1i(lit_u.textured, textured ? 1 : 0);
        if (textured) glBindTextureUnit(0, r.entry->texture);
        glBindVertexArray(r.entry->buffers.vao);
        if (mesh.ranges.empty()) {
            const Vec3 c = clamp01(mesh.color);
            glUniform4f(lit_u.color, c.x(), c.y(), c.z(), 1.0f);
            glDrawElements(GL_TRIANGLES, r.entry->buffers.index_count, GL_UNSIGNED_INT, nullptr);
            continue;
        }
        for (const DrawRange& range : mesh.ranges) {
            const Vec3 c = clamp01(range.color);
            glUniform4f(lit_u.color, c.x(), c.y(), c.z(), 1.0f);
            glDrawElements(GL_TRIANGLES, GLsizei(range.index_count), GL_UNSIGNED_INT,
                           reinterpret_cast<const void*>(std::uintptr_t(range.first_index) * sizeof(std::uint32_t)));
        }
    }
}

// Translucent, front faces only, no depth writes.
void Renderer::Impl::draw_ellipsoids(const FrameView& view, const DrawList& list) {
    if (!show_ellipsoids) return;
    glUseProgram(lit);
    glUniformMatrix4fv(lit_u.view_projection, 1, GL_FALSE, view.view_projection.data());
    glUniform3fv(lit_u.eye, 1, view.eye.data());
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glDepthMask(GL_FALSE);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glUniform1i(lit_u.two_sided, 0);
    glUniform1f(lit_u.specular, 0.3f);
    glUniform1f(lit_u.shininess, 12.0f);
    glUniform1f(lit_u.rim, 0.15f);
    const Vec4& c = list.ellipsoid_color;
    glUniform4f(lit_u.color, c.x(), c.y(), c.z(), c.w());
    glBindVertexArray(sphere.vao);
    for (const Affine3& world : list.ellipsoids) {
        if (!world.matrix().allFinite() || std::abs(world.linear().determinant()) < Real(1e-12)) continue;
        const Mat4 model = world.matrix();
        const Mat3 normals = normal_matrix(world);
        glUniformMatrix4fv(lit_u.model, 1, GL_FALSE, model.data());
        glUniformMatrix3fv(lit_u.normal_matrix, 1, GL_FALSE, normals.data());
        glDrawElements(GL_TRIANGLES, sphere.index_count, GL_UNSIGNED_INT, nullptr);
    }
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
}

void Renderer::Impl::resolve() {
    glBindVertexArray(0);
    const GLsizei w = settings.width, h = settings.height;
    if (resolve_fbo != 0)
        glBlitNamedFramebuffer(draw_fbo, resolve_fbo, 0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    if (const GLenum error = glGetError(); error != GL_NO_ERROR)
        note("OpenGL error 0x" + [error] {
            char buffer[16];
            std::snprintf(buffer, sizeof buffer, "%04x", unsigned(error));
            return std::string(buffer);
        }() + " while drawing the frame");
}

// The overlay goes onto the frame read_pixels() and present() use (after the resolve, so
// it is drawn once, without multisampling), blended, with no depth test. The vertex
// buffer grows when needed and is otherwise rewritten in place.
void Renderer::Impl::draw_hud(const HudOverlay& overlay) {
    render_detail::layout_hud(overlay, settings.width, settings.height, hud_vertices);
    if (hud_vertices.empty()) return;
    const auto bytes = GLsizeiptr(hud_vertices.size() * sizeof(render_detail::HudVertex));
    if (bytes > hud_buffer_bytes) {
        hud_buffer_bytes = std::max(bytes, GLsizeiptr(64 * 1024));
        glNamedBufferData(hud_buffer, hud_buffer_bytes, nullptr, GL_DYNAMIC_DRAW);
    }
    glNamedBufferSubData(hud_buffer, 0, bytes, hud_vertices.data());
    glBindFramebuffer(GL_FRAMEBUFFER, read_fbo());
    glViewport(0, 0, settings.width, settings.height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glDisable(GL_STENCIL_TEST);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(hud);
    glUniform2f(hud_frame_size, float(settings.width), float(settings.height));
    glBindVertexArray(hud_vao);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(hud_vertices.size()));
    glBindVertexArray(0);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
    if (const GLenum error = glGetError(); error != GL_NO_ERROR)
        note("OpenGL error " + std::to_string(error) + " while drawing the overlay");
}

// ---------------------------------------------------------------------------------------

Renderer::Renderer(std::unique_ptr<Impl> impl) : m_impl(std::move(impl)) {}
Renderer::~Renderer() = default;

Result<std::unique_ptr<Renderer>> Renderer::create(const RenderSettings& settings) {
    if (auto ok = validate(settings); !ok) return fail(ok.error().message);
    auto impl = std::make_unique<Impl>();
    impl->settings = settings;
    if (settings.target == RenderTarget::window) {
        auto window = X11Window::create(settings.width, settings.height, settings.window_title);
        if (!window) return fail(window.error().message);
        impl->window = std::move(*window);
        auto context = EglContext::create_window(impl->window->display(), impl->window->window(), settings.vsync);
        if (!context) return fail(context.error().message);
        impl->context = std::move(*context);
    } else {
        auto context = EglContext::create_offscreen();
        if (!context) return fail(context.error().message);
        impl->context = std::move(*context);
    }
    GLint major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    auto text = [](GLenum name) {
        const auto* s = glGetString(name);
        return s != nullptr ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
    };
    impl->info.platform = impl->context->platform();
    impl->info.gl_vendor = text(GL_VENDOR);
    impl->info.gl_renderer = text(GL_RENDERER);
    impl->info.gl_version = text(GL_VERSION);
    if (major * 10 + minor < 45)
        return fail("OpenGL: version " + impl->info.gl_version + " on " + impl->info.gl_renderer +
                    "; Drape needs 4.5 core");
    if (auto ok = impl->create_programs(); !ok) return fail(ok.error().message);
    if (auto ok = impl->create_framebuffers(); !ok) return fail(ok.error().message);
    impl->create_sphere();
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
}

Camera& Renderer::camera() noexcept { return m_impl->camera; }
const Camera& Renderer::camera() const noexcept { return m_impl->camera; }
const RenderSettings& Renderer::settings() const noexcept { return m_impl->settings; }
const RendererInfo& Renderer::info() const noexcept { return m_impl->info; }
int Renderer::width() const noexcept { return m_impl->settings.width; }
int Renderer::height() const noexcept { return m_impl->settings.height; }
void Renderer::set_show_ellipsoids(bool show) noexcept { m_impl->show_ellipsoids = show; }
bool Renderer::show_ellipsoids() const noexcept { return m_impl->show_ellipsoids; }

void Renderer::draw(const DrawList& list) {
    if (!m_impl->context->make_current()) {
        m_impl->frame_error = "EGL: cannot make the renderer's context current";
        return;
    }
    m_impl->draw(list);
}

void Renderer::draw_hud(const HudOverlay& hud) {
    if (!m_impl->drawn) return;
    if (!m_impl->context->make_current()) {
        m_impl->frame_error = "EGL: cannot make the renderer's context current";
        return;
    }
    m_impl->draw_hud(hud);
}

void Renderer::set_window_title(const std::string& title) {
    if (m_impl->window) m_impl->window->set_title(title);
}

Result<void> Renderer::read_pixels(Image& into) {
    Impl& r = *m_impl;
    if (!r.frame_error.empty()) return fail("render: " + r.frame_error);
    if (!r.drawn) return fail("render: read_pixels before any frame was drawn");
    if (!r.context->make_current()) return fail("EGL: cannot make the renderer's context current");
    const int w = r.settings.width, h = r.settings.height;
    const std::size_t row = std::size_t(w) * 4;
    r.readback.resize(row * std::size_t(h));
    glBindFramebuffer(GL_READ_FRAMEBUFFER, r.read_fbo());
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, r.readback.data());
    if (const GLenum error = glGetError(); error != GL_NO_ERROR)
        return fail("OpenGL: glReadPixels failed (GL error " + std::to_string(error) + ")");
    into.width = w;
    into.height = h;
    into.rgba.resize(row * std::size_t(h));
    for (int y = 0; y < h; ++y)  // GL's rows start at the bottom; Image's at the top
        std::memcpy(into.rgba.data() + std::size_t(y) * row, r.readback.data() + std::size_t(h - 1 - y) * row, row);
    return {};
}

Result<Image> Renderer::read_pixels() {
    Image image;
    if (auto ok = read_pixels(image); !ok) return fail(ok.error().message);
    return image;
}

Result<void> Renderer::present() {
    Impl& r = *m_impl;
    if (!r.context->make_current()) return fail("EGL: cannot make the renderer's context current");
    if (!r.frame_error.empty()) return fail("render: " + r.frame_error);
    if (!r.context->has_window()) {
        glFinish();
        return {};
    }
    const int w = r.settings.width, h = r.settings.height;
    glBlitNamedFramebuffer(r.read_fbo(), 0, 0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    return r.context->swap_buffers();
}

bool Renderer::poll_events(InputState& input) {
    input.clear();
    if (!m_impl->window) return true;
    const bool open = m_impl->window->poll(input);
    if (input.orbit_dx_px != 0 || input.orbit_dy_px != 0) m_impl->camera.orbit(input.orbit_dx_px, input.orbit_dy_px);
    if (input.zoom_steps != 0) m_impl->camera.zoom(input.zoom_steps);
    return open;
}

void Renderer::finish() {
    if (m_impl->context->make_current()) glFinish();
}

}  // namespace drape
