#include "drape/engine/render/egl_context.hpp"

#include <cstdio>
#include <cstring>
#include <string_view>
#include <vector>

#include <EGL/eglext.h>

namespace drape::render_detail {
namespace {

bool has_extension(const char* list, std::string_view name) {
    if (list == nullptr) return false;
    std::string_view all(list);
    for (std::size_t pos = 0; (pos = all.find(name, pos)) != std::string_view::npos; pos += name.size()) {
        const bool starts = pos == 0 || all[pos - 1] == ' ';
        const bool ends = pos + name.size() == all.size() || all[pos + name.size()] == ' ';
        if (starts && ends) return true;
    }
    return false;
}

std::string last_error() { return egl_error_name(eglGetError()); }

/// Initialises a platform display; on failure says why and leaves nothing open.
Result<EGLDisplay> initialise(EGLDisplay display, const char* what) {
    if (display == EGL_NO_DISPLAY) return fail(std::string(what) + ": no display (" + last_error() + ")");
    EGLint major = 0, minor = 0;
    if (eglInitialize(display, &major, &minor) == EGL_FALSE)
        return fail(std::string(what) + ": eglInitialize failed (" + last_error() + ")");
    return display;
}

}  // namespace

std::string egl_error_name(EGLint code) {
    switch (code) {
        case EGL_SUCCESS: return "EGL_SUCCESS";
        case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
        case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
        case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
        case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
        case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
        case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
        case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
        case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
        case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
        case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
        case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
        case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
        case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
        case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
        default: return "EGL error 0x" + [code] {
            char buffer[16];
            std::snprintf(buffer, sizeof buffer, "%04x", static_cast<unsigned>(code));
            return std::string(buffer);
        }();
    }
}

Result<std::unique_ptr<EglContext>> EglContext::create_offscreen() {
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (client == nullptr || !has_extension(client, "EGL_EXT_platform_base"))
        return fail("EGL: the EGL library offers no platform displays (EGL_EXT_platform_base missing); "
                    "install Mesa's EGL (Debian: libegl-mesa0)");
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display == nullptr) return fail("EGL: eglGetPlatformDisplayEXT is missing");

    std::unique_ptr<EglContext> context(new EglContext());
    std::string tried;
    // 1. Mesa's surfaceless platform: no window system, no device node needed.
    if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
        auto display = initialise(get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr),
                                  "surfaceless");
        if (display) {
            context->m_display = *display;
            context->m_platform = "surfaceless";
            if (auto made = context->create_context(nullptr); made) return context;
            else tried += made.error().message + "; ";
            context->m_display = EGL_NO_DISPLAY;
        } else {
            tried += display.error().message + "; ";
        }
    } else {
        tried += "surfaceless: EGL_MESA_platform_surfaceless missing; ";
    }
    // 2. EGL devices (a GPU's render node, or Mesa's software device).
    auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    if (has_extension(client, "EGL_EXT_platform_device") && query_devices != nullptr) {
        EGLDeviceEXT devices[16];
        EGLint count = 0;
        if (query_devices(16, devices, &count) == EGL_FALSE || count == 0) tried += "device: no EGL device; ";
        for (EGLint i = 0; i < count; ++i) {
            auto display = initialise(get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr), "device");
            if (!display) {
                tried += display.error().message + "; ";
                continue;
            }
            context->m_display = *display;
            context->m_platform = "device";
            if (auto made = context->create_context(nullptr); made) return context;
            else tried += made.error().message + "; ";
            context->m_display = EGL_NO_DISPLAY;
        }
    } else {
        tried += "device: EGL_EXT_platform_device missing; ";
    }
    if (tried.size() >= 2) tried.resize(tried.size() - 2);
    return fail("EGL: no off-screen OpenGL 4.5 core context (" + tried + ")");
}

Result<std::unique_ptr<EglContext>> EglContext::create_window(void* x_display, unsigned long x_window, bool vsync) {
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!has_extension(client, "EGL_KHR_platform_x11") && !has_extension(client, "EGL_EXT_platform_x11"))
        return fail("EGL: no X11 platform (EGL_KHR_platform_x11 missing)");
    if (get_platform_display == nullptr) return fail("EGL: eglGetPlatformDisplayEXT is missing");
    auto display = initialise(get_platform_display(EGL_PLATFORM_X11_KHR, x_display, nullptr), "EGL x11");
    if (!display) return fail(display.error().message);

    std::unique_ptr<EglContext> context(new EglContext());
    context->m_display = *display;
    context->m_platform = "x11";
    context->m_terminate = true;  // this display belongs to our own X connection
    const EGLint attributes[] = {EGL_SURFACE_TYPE, EGL_WINDOW_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                 EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint found = 0;
    if (eglChooseConfig(*display, attributes, &config, 1, &found) == EGL_FALSE || found == 0)
        return fail("EGL x11: no RGB8 window config for OpenGL (" + last_error() + ")");
    context->m_surface = eglCreateWindowSurface(*display, config, static_cast<EGLNativeWindowType>(x_window), nullptr);
    if (context->m_surface == EGL_NO_SURFACE)
        return fail("EGL x11: cannot create a window surface (" + last_error() + ")");
    if (auto made = context->create_context(config); !made) return fail(made.error().message);
    eglSwapInterval(*display, vsync ? 1 : 0);
    return context;
}

Result<void> EglContext::create_context(EGLConfig config) {
    const char* extensions = eglQueryString(m_display, EGL_EXTENSIONS);
    if (eglBindAPI(EGL_OPENGL_API) == EGL_FALSE) return fail(m_platform + ": no desktop OpenGL API");
    EGLSurface pbuffer = EGL_NO_SURFACE;
    if (config == nullptr && !has_extension(extensions, "EGL_KHR_no_config_context")) {
        // Configs here may be pbuffer-only: choose one of those.
        const EGLint attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLint found = 0;
        if (eglChooseConfig(m_display, attributes, &config, 1, &found) == EGL_FALSE || found == 0)
            return fail(m_platform + ": no pbuffer config for OpenGL");
    }
    const EGLint attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                 EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    m_context = eglCreateContext(m_display, config == nullptr ? EGL_NO_CONFIG_KHR : config, EGL_NO_CONTEXT, attributes);
    if (m_context == EGL_NO_CONTEXT)
        return fail(m_platform + ": no OpenGL 4.5 core context (" + last_error() + ")");
    if (m_surface == EGL_NO_SURFACE && !has_extension(extensions, "EGL_KHR_surfaceless_context")) {
        const EGLint size[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
        pbuffer = eglCreatePbufferSurface(m_display, config, size);
        if (pbuffer == EGL_NO_SURFACE) return fail(m_platform + ": cannot create a pbuffer (" + last_error() + ")");
        m_surface = pbuffer;
    }
    if (eglMakeCurrent(m_display, m_surface, m_surface, m_context) == EGL_FALSE)
        return fail(m_platform + ": cannot make the OpenGL context current (" + last_error() + ")");
    return {};
}

EglContext::~EglContext() {
    if (m_display == EGL_NO_DISPLAY) return;
    if (eglGetCurrentContext() == m_context) eglMakeCurrent(m_display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (m_context != EGL_NO_CONTEXT) eglDestroyContext(m_display, m_context);
    if (m_surface != EGL_NO_SURFACE) eglDestroySurface(m_display, m_surface);
    // Surfaceless and device displays are shared by every context of the process (EGL hands
    // out one handle per platform): terminating one would break the others.
    if (m_terminate) eglTerminate(m_display);
}

bool EglContext::make_current() {
    if (eglGetCurrentContext() == m_context) return true;
    return eglMakeCurrent(m_display, m_surface, m_surface, m_context) == EGL_TRUE;
}

Result<void> EglContext::swap_buffers() {
    if (m_surface == EGL_NO_SURFACE || m_platform != "x11") return {};
    if (eglSwapBuffers(m_display, m_surface) == EGL_FALSE)
        return fail("EGL x11: eglSwapBuffers failed (" + last_error() + ")");
    return {};
}

}  // namespace drape::render_detail
