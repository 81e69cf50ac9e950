// One frame in a real X11 window under Xvfb (a virtual X server the test starts itself),
// read back, plus keys and mouse drags delivered as X events. Skips only when Xvfb is not
// installed (scripts/setup.sh installs it).
#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include "drape/engine/render/renderer.hpp"
#include "drape/systems/render_system.hpp"
#include "tests/render/test_scene.hpp"

// After Eigen: Xlib defines macros (Success, None, Status) that clash with it.
#if __has_include(<X11/Xlib.h>)
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <X11/keysym.h>
#include "tests/test_paths.hpp"
#define DRAPE_TEST_HAVE_X11 1
#endif


namespace drape {
namespace {

std::string find_in_path(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::string all = path != nullptr ? path : "/usr/bin:/bin";
    for (std::size_t start = 0; start <= all.size();) {
        const std::size_t end = std::min(all.find(':', start), all.size());
        const auto candidate = std::filesystem::path(all.substr(start, end - start)) / program;
        if (::access(candidate.c_str(), X_OK) == 0) return candidate.string();
        start = end + 1;
    }
    return {};
}

/// An Xvfb server on a display it picks itself (-displayfd); stopped by the destructor.
class Xvfb {
public:
    explicit Xvfb(const std::string& binary) {
        int fds[2];
        if (::pipe(fds) != 0) return;
        m_pid = ::fork();
        if (m_pid == 0) {
            ::close(fds[0]);
            const int null = ::open("/dev/null", O_WRONLY);
            if (null >= 0) { ::dup2(null, 1); ::dup2(null, 2); }
            const std::string fd = std::to_string(fds[1]);
            ::execl(binary.c_str(), "Xvfb", "-displayfd", fd.c_str(), "-screen", "0", "640x480x24", "-nolisten", "tcp",
                    static_cast<char*>(nullptr));
            ::_exit(127);
        }
        ::close(fds[1]);
        if (m_pid < 0) {
            ::close(fds[0]);
            return;
        }
        // Xvfb writes the display number once it accepts connections.
        std::string number;
        pollfd p{fds[0], POLLIN, 0};
        while (::poll(&p, 1, 15000) > 0) {
            char c = 0;
            if (::read(fds[0], &c, 1) != 1 || c == '\n') break;
            number += c;
        }
        ::close(fds[0]);
        if (!number.empty()) m_display = ":" + number;
    }
    ~Xvfb() {
        if (m_pid > 0) {
            ::kill(m_pid, SIGTERM);
            int status = 0;
            ::waitpid(m_pid, &status, 0);
        }
    }
    [[nodiscard]] const std::string& display() const { return m_display; }

private:
    pid_t m_pid = -1;
    std::string m_display;
};

/// Sets DISPLAY for the scope, restores it after.
class DisplayVariable {
public:
    explicit DisplayVariable(const std::string& value) {
        if (const char* old = std::getenv("DISPLAY")) m_old = old, m_had = true;
        ::setenv("DISPLAY", value.c_str(), 1);
    }
    ~DisplayVariable() {
        if (m_had) ::setenv("DISPLAY", m_old.c_str(), 1);
        else ::unsetenv("DISPLAY");
    }

private:
    std::string m_old;
    bool m_had = false;
};

#ifdef DRAPE_TEST_HAVE_X11
/// The top-level window with this title, searched on a separate connection.
Window find_window(Display* display, Window parent, const std::string& title) {
    Window root = 0, parent_of = 0, *children = nullptr;
    unsigned count = 0;
    if (XQueryTree(display, parent, &root, &parent_of, &children, &count) == 0) return 0;
    Window found = 0;
    for (unsigned i = 0; i < count && found == 0; ++i) {
        char* name = nullptr;
        if (XFetchName(display, children[i], &name) != 0 && name != nullptr) {
            if (title == name) found = children[i];
            XFree(name);
        }
        if (found == 0) found = find_window(display, children[i], title);
    }
    if (children != nullptr) XFree(children);
    return found;
}

void send(Display* display, Window window, XEvent event, long mask) {
    event.xany.display = display;
    event.xany.window = window;
    XSendEvent(display, window, True, mask, &event);
}
#endif

TEST(RenderWindow, OneFrameRendersInAnXvfbWindowAndReadsBack) {
    const std::string binary = find_in_path("Xvfb");
    if (binary.empty()) GTEST_SKIP() << "Xvfb is not installed (Debian: xvfb; scripts/test installs it)";
    Xvfb server(binary);
    ASSERT_FALSE(server.display().empty()) << "Xvfb did not start";
    DisplayVariable display(server.display());

    RenderSettings settings;
    settings.width = 256;
    settings.height = 192;
    settings.target = RenderTarget::window;
    settings.window_title = "Drape render test";
    auto created = Renderer::create(settings);
    ASSERT_TRUE(created.has_value()) << created.error().message;
    Renderer& renderer = **created;
    EXPECT_EQ(renderer.info().platform, "x11");

    Registry registry;
    registry.emplace<SkinnedMesh>(registry.create(),
                                  test::make_cylinder_body(0, 0, 0.25f, 1.6f, Vec3(0.1f, 0.2f, 0.85f)));
    const Entity garment = registry.create();
    registry.emplace<Garment>(garment, test::make_panel(-0.4f, 0.3f, 0.3f, 0.8f, 9, Vec3(0.1f, 0.8f, 0.1f)));
    Camera& camera = renderer.camera();
    camera.follow = false;
    camera.target = Vec3(0, 0.7f, 0);
    camera.yaw_rad = 0;

    InputState input;
    EXPECT_TRUE(renderer.poll_events(input));
    draw_registry(renderer, registry);
    ASSERT_TRUE(renderer.present().has_value());
    auto image = renderer.read_pixels();
    ASSERT_TRUE(image.has_value()) << image.error().message;
    ASSERT_EQ(image->width, 256);
    const auto centre = camera.project(registry.get<Garment>(garment).state.x.rowwise().mean(), 256, 192);
    ASSERT_TRUE(centre);
    const std::uint8_t* p = image->at(int(centre->x_px), int(centre->y_px));
    EXPECT_GT(int(p[1]), int(p[0]) + 60) << "green garment expected, got " << int(p[0]) << "," << int(p[1]) << ","
                                          << int(p[2]);
    ASSERT_TRUE(write_png(*image, test::binary_dir() / "render-test-output" / "window.png"));

#ifdef DRAPE_TEST_HAVE_X11
    // Keys and a mouse drag, as a user would give them.
    Display* x = XOpenDisplay(server.display().c_str());
    ASSERT_NE(x, nullptr);
    const Window window = find_window(x, DefaultRootWindow(x), settings.window_title);
    ASSERT_NE(window, 0u) << "the renderer's window was not found by its title";
    // What present() put on the screen: the same garment pixel, read from the X server.
    XImage* shown = XGetImage(x, window, 0, 0, 256, 192, AllPlanes, ZPixmap);
    ASSERT_NE(shown, nullptr);
    const unsigned long on_screen = XGetPixel(shown, int(centre->x_px), int(centre->y_px));
    const int screen_r = int((on_screen >> 16) & 0xff), screen_g = int((on_screen >> 8) & 0xff);
    XDestroyImage(shown);
    EXPECT_GT(screen_g, screen_r + 60) << "the window shows the frame: " << screen_r << "," << screen_g;
    for (KeySym key : {XK_space, XK_n, XK_e, XK_m, XK_r, XK_h, XK_Escape}) {
        XEvent event{};
        event.type = KeyPress;
        event.xkey.keycode = XKeysymToKeycode(x, key);
        event.xkey.same_screen = True;
        send(x, window, event, KeyPressMask);
    }
    XEvent press{};
    press.type = ButtonPress;
    press.xbutton.button = Button1;
    press.xbutton.x = 100;
    press.xbutton.y = 100;
    send(x, window, press, ButtonPressMask);
    XEvent motion{};
    motion.type = MotionNotify;
    motion.xmotion.x = 140;
    motion.xmotion.y = 90;
    send(x, window, motion, PointerMotionMask);
    XEvent release = press;
    release.type = ButtonRelease;
    send(x, window, release, ButtonReleaseMask);
    XSync(x, False);
    XCloseDisplay(x);

    const Real yaw_before = camera.yaw_rad;
    for (int tries = 0; tries < 100 && input.actions.size() < 7; ++tries) {
        InputState more;
        renderer.poll_events(more);
        input.actions.insert(input.actions.end(), more.actions.begin(), more.actions.end());
        input.orbit_dx_px += more.orbit_dx_px;
        ::usleep(10000);
    }
    const std::vector<Action> expected{Action::toggle_pause, Action::step,  Action::toggle_ellipsoids,
                                       Action::switch_model, Action::reset, Action::toggle_hud, Action::quit};
    EXPECT_EQ(input.actions, expected);
    EXPECT_FLOAT_EQ(input.orbit_dx_px, 40.0f);
    EXPECT_NE(camera.yaw_rad, yaw_before) << "a drag orbits the camera";

    // The title follows set_window_title (drape play shows the fps and ms there).
    renderer.set_window_title("Drape  60 fps  16.7 ms");
    Display* y = XOpenDisplay(server.display().c_str());
    ASSERT_NE(y, nullptr);
    EXPECT_NE(find_window(y, DefaultRootWindow(y), "Drape  60 fps  16.7 ms"), 0u) << "the new title is not shown";
    XCloseDisplay(y);
#endif
}

}  // namespace
}  // namespace drape
