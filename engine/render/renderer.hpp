// Drape's renderer: an OpenGL 4.5 core context through EGL, off-screen or in an X11 window.
//
// Off-screen it uses Mesa's surfaceless platform (EGL_MESA_platform_surfaceless) and falls
// back to the EGL device platform (EGL_EXT_platform_device); no display or GPU is needed
// (Mesa's llvmpipe renders on the CPU). In a window it uses an EGL window surface on X11.
// Either way a frame is drawn into a framebuffer object (4x MSAA on a GPU), resolved,
// then read back (`read_pixels`) or shown (`present`).
//
// The renderer draws what it is given (a DrawList of meshes and debug ellipsoids) and
// knows nothing of the scene's components; systems/render_system.cpp builds the list.
//
// This header holds no EGL or GL type, so code outside engine/render builds the same with
// or without the render module. One Renderer owns one context; it makes it current on the
// calling thread before each GL call, so use a Renderer from one thread at a time.
#pragma once

#include <memory>
#include <string>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/math.hpp"
#include "drape/engine/render/camera.hpp"
#include "drape/engine/render/draw_list.hpp"
#include "drape/engine/render/hud.hpp"
#include "drape/engine/render/image.hpp"
#include "drape/engine/render/input.hpp"

namespace drape {

enum class RenderTarget : std::uint8_t {
    offscreen,  ///< EGL surfaceless (or device) platform, no display needed.
    window,     ///< An X11 window of the requested size (needs DISPLAY).
};

struct RenderSettings {
    int width = 1280;                      ///< px, 16..8192.
    int height = 720;                      ///< px, 16..8192.
    RenderTarget target = RenderTarget::offscreen;
    /// Multisample anti-aliasing: 0 or 1 off; 2, 4, 8, 16 (capped by the driver); -1 automatic:
    /// 4 on a GPU, off on a software rasteriser (on llvmpipe 4x MSAA triples a frame's cost).
    int msaa_samples = -1;
    Vec3 clear_color = Vec3(0.45f, 0.60f, 0.82f);  ///< Sky, linear RGB.
    std::string window_title = "Drape";
    bool vsync = false;                    ///< Window only: wait for the display's refresh in present().
};

/// Checks settings; the error names the field.
[[nodiscard]] Result<void> validate(const RenderSettings& settings);

/// What the context turned out to be (for logs and reports).
struct RendererInfo {
    std::string platform;      ///< "surfaceless", "device" or "x11".
    std::string gl_vendor;
    std::string gl_renderer;   ///< e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    std::string gl_version;
    int msaa_samples = 0;      ///< Samples actually used (0 = off).
};

class Renderer {
public:
    /// Opens the context and the frame buffers. Fails with one clear message when there is
    /// no display (window), no EGL, no OpenGL 4.5 core, or a shader does not compile.
    [[nodiscard]] static Result<std::unique_ptr<Renderer>> create(const RenderSettings& settings);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    [[nodiscard]] Camera& camera() noexcept;
    [[nodiscard]] const Camera& camera() const noexcept;
    [[nodiscard]] const RenderSettings& settings() const noexcept;
    [[nodiscard]] const RendererInfo& info() const noexcept;
    [[nodiscard]] int width() const noexcept;
    [[nodiscard]] int height() const noexcept;

    /// Whether draw() shows a list's debug ellipsoids (the window's E key).
    void set_show_ellipsoids(bool show) noexcept;
    [[nodiscard]] bool show_ellipsoids() const noexcept;

    /// Draws a frame: the ground with the contact shadows of the meshes that ask for one,
    /// planar shadows of the casters, the meshes lit in list order, and the list's
    /// ellipsoids when shown. Bad data (an index past the vertices, a range past the
    /// triangles) skips that mesh; it and the list's own problems are reported by the next
    /// read_pixels()/present().
    void draw(const DrawList& list);

    /// Draws the heads-up overlay (engine/render/hud.hpp) over the last drawn frame, in its
    /// top-left corner; read_pixels() and present() then show it. Call after draw().
    void draw_hud(const HudOverlay& hud);

    /// Window: replaces the window's title. Off-screen: does nothing.
    void set_window_title(const std::string& title);

    /// The last drawn frame, RGBA8, top row first. Also reports an error of the last draw.
    [[nodiscard]] Result<Image> read_pixels();
    /// The same into an existing image (no allocation once it has the right size).
    [[nodiscard]] Result<void> read_pixels(Image& into);
    /// Window: shows the last drawn frame (swap buffers). Off-screen: waits for the GPU.
    [[nodiscard]] Result<void> present();
    /// Window: gathers key and mouse events (mouse drags orbit the camera, the wheel zooms)
    /// and returns false once the window is closed. Off-screen: clears `input`, returns true.
    bool poll_events(InputState& input);

    /// Blocks until the GPU finished every command given so far (for timing).
    void finish();

private:
    struct Impl;
    explicit Renderer(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> m_impl;
};

}  // namespace drape
