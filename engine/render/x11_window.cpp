#include "drape/engine/render/x11_window.hpp"

#include <cstdlib>

#ifdef DRAPE_HAVE_X11
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/keysym.h>
#endif

namespace drape::render_detail {

#ifdef DRAPE_HAVE_X11

namespace {
Display* as_display(void* p) { return static_cast<Display*>(p); }
}  // namespace

Result<std::unique_ptr<X11Window>> X11Window::create(int width, int height, const std::string& title) {
    const char* name = std::getenv("DISPLAY");
    if (name == nullptr || *name == '\0')
        return fail("window: DISPLAY is not set (no X server to open a window on; render off-screen instead)");
    Display* display = XOpenDisplay(nullptr);
    if (display == nullptr) return fail(std::string("window: cannot open X display \"") + name + "\"");
    std::unique_ptr<X11Window> window(new X11Window());
    window->m_display = display;
    const int screen = DefaultScreen(display);
    window->m_window = XCreateSimpleWindow(display, RootWindow(display, screen), 0, 0, static_cast<unsigned>(width),
                                           static_cast<unsigned>(height), 0, BlackPixel(display, screen),
                                           BlackPixel(display, screen));
    if (window->m_window == 0) return fail("window: XCreateSimpleWindow failed");
    XStoreName(display, window->m_window, title.c_str());
    // Fixed size: the frame buffers are allocated once for the requested size.
    XSizeHints* hints = XAllocSizeHints();
    if (hints != nullptr) {
        hints->flags = PMinSize | PMaxSize;
        hints->min_width = hints->max_width = width;
        hints->min_height = hints->max_height = height;
        XSetWMNormalHints(display, window->m_window, hints);
        XFree(hints);
    }
    Atom delete_atom = XInternAtom(display, "WM_DELETE_WINDOW", False);
    XSetWMProtocols(display, window->m_window, &delete_atom, 1);
    window->m_delete_atom = delete_atom;
    XSelectInput(display, window->m_window,
                 KeyPressMask | ButtonPressMask | ButtonReleaseMask | PointerMotionMask | StructureNotifyMask);
    XMapWindow(display, window->m_window);
    XFlush(display);
    return window;
}

X11Window::~X11Window() {
    if (m_display == nullptr) return;
    if (m_window != 0) XDestroyWindow(as_display(m_display), m_window);
    XCloseDisplay(as_display(m_display));
}

bool X11Window::poll(InputState& input) {
    Display* display = as_display(m_display);
    while (m_open && XPending(display) > 0) {
        XEvent event;
        XNextEvent(display, &event);
        switch (event.type) {
            case KeyPress: {
                const KeySym key = XLookupKeysym(&event.xkey, 0);
                switch (key) {
                    case XK_space: input.actions.push_back(Action::toggle_pause); break;
                    case XK_n: input.actions.push_back(Action::step); break;
                    case XK_e: input.actions.push_back(Action::toggle_ellipsoids); break;
                    case XK_m: input.actions.push_back(Action::switch_model); break;
                    case XK_r: input.actions.push_back(Action::reset); break;
                    case XK_h: input.actions.push_back(Action::toggle_hud); break;
                    case XK_q:
                    case XK_Escape: input.actions.push_back(Action::quit); break;
                    default: break;
                }
                break;
            }
            case ButtonPress:
                if (event.xbutton.button == Button1) {
                    m_dragging = true;
                    m_last_x = event.xbutton.x;
                    m_last_y = event.xbutton.y;
                } else if (event.xbutton.button == Button4) {
                    input.zoom_steps += 1;
                } else if (event.xbutton.button == Button5) {
                    input.zoom_steps -= 1;
                }
                break;
            case ButtonRelease:
                if (event.xbutton.button == Button1) m_dragging = false;
                break;
            case MotionNotify:
                if (m_dragging) {
                    input.orbit_dx_px += static_cast<float>(event.xmotion.x - m_last_x);
                    input.orbit_dy_px += static_cast<float>(event.xmotion.y - m_last_y);
                    m_last_x = event.xmotion.x;
                    m_last_y = event.xmotion.y;
                }
                break;
            case ClientMessage:
                if (static_cast<unsigned long>(event.xclient.data.l[0]) == m_delete_atom) {
                    input.actions.push_back(Action::quit);
                    m_open = false;
                }
                break;
            case DestroyNotify: m_open = false; break;
            default: break;
        }
    }
    input.window_open = m_open;
    return m_open;
}

#else  // built without X11 headers

Result<std::unique_ptr<X11Window>> X11Window::create(int, int, const std::string&) {
    return fail("window: Drape was built without X11 (install libx11-dev and rebuild), render off-screen instead");
}
X11Window::~X11Window() = default;
bool X11Window::poll(InputState& input) {
    input.window_open = false;
    return false;
}

#endif

void X11Window::set_title(const std::string& title) {
    auto* display = static_cast<Display*>(m_display);
    XStoreName(display, m_window, title.c_str());
    XFlush(display);
}

}  // namespace drape::render_detail
