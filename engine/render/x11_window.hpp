// A fixed-size X11 window that reports keys and mouse drags. Internal to engine/render.
#pragma once

#include <memory>
#include <string>

#include "drape/engine/core/error.hpp"
#include "drape/engine/render/input.hpp"

namespace drape::render_detail {

class X11Window {
public:
    /// Opens the display named by $DISPLAY and maps a width x height window.
    [[nodiscard]] static Result<std::unique_ptr<X11Window>> create(int width, int height, const std::string& title);
    ~X11Window();
    X11Window(const X11Window&) = delete;
    X11Window& operator=(const X11Window&) = delete;

    [[nodiscard]] void* display() const noexcept { return m_display; }   ///< Xlib Display*.
    [[nodiscard]] unsigned long window() const noexcept { return m_window; }

    /// Drains pending events into `input` (actions, drag and wheel). False once closed.
    bool poll(InputState& input);
    /// Replaces the title the window manager shows.
    void set_title(const std::string& title);

private:
    X11Window() = default;
    void* m_display = nullptr;
    unsigned long m_window = 0;
    unsigned long m_delete_atom = 0;
    bool m_open = true;
    bool m_dragging = false;
    int m_last_x = 0;
    int m_last_y = 0;
};

}  // namespace drape::render_detail
