// An EGL display + OpenGL 4.5 core context: off-screen (surfaceless, device) or on an
// X11 window surface. Internal to engine/render.
#pragma once

#include <memory>
#include <string>

#include <EGL/egl.h>

#include "drape/engine/core/error.hpp"

namespace drape::render_detail {

class EglContext {
public:
    /// Off-screen: Mesa's surfaceless platform, else the first EGL device that works.
    [[nodiscard]] static Result<std::unique_ptr<EglContext>> create_offscreen();
    /// On a window: `x_display` is an Xlib Display*, `x_window` its Window.
    [[nodiscard]] static Result<std::unique_ptr<EglContext>> create_window(void* x_display, unsigned long x_window,
                                                                          bool vsync);
    ~EglContext();
    EglContext(const EglContext&) = delete;
    EglContext& operator=(const EglContext&) = delete;

    /// Makes the context current on this thread if it is not already.
    [[nodiscard]] bool make_current();
    /// Window: eglSwapBuffers. Off-screen: nothing.
    [[nodiscard]] Result<void> swap_buffers();
    [[nodiscard]] const std::string& platform() const noexcept { return m_platform; }
    [[nodiscard]] bool has_window() const noexcept { return m_platform == "x11"; }

private:
    EglContext() = default;
    [[nodiscard]] Result<void> create_context(EGLConfig config);

    EGLDisplay m_display = EGL_NO_DISPLAY;
    EGLContext m_context = EGL_NO_CONTEXT;
    EGLSurface m_surface = EGL_NO_SURFACE;
    bool m_terminate = false;  ///< Only a display this object alone uses is terminated.
    std::string m_platform;
};

/// Readable name of an EGL error code ("EGL_BAD_MATCH").
[[nodiscard]] std::string egl_error_name(EGLint code);

}  // namespace drape::render_detail
