// What the window reports to the game loop: user actions and the mouse.
//
// The renderer turns X11 key presses into `Action`s (the game decides what each does)
// and applies mouse drags to its orbit camera itself; the raw drag is reported too.
#pragma once

#include <cstdint>
#include <vector>

namespace drape {

/// A user request from the keyboard or the window manager.
enum class Action : std::uint8_t {
    toggle_pause,     ///< Space.
    step,             ///< N: advance one frame while paused.
    toggle_ellipsoids,///< E: show or hide the collision ellipsoids.
    switch_model,     ///< M: simplified <-> classic garment model.
    reset,            ///< R: restart the scene.
    toggle_hud,       ///< H: show or hide the frame budget overlay.
    quit,             ///< Q, Escape, or the window's close button.
};

[[nodiscard]] constexpr const char* action_name(Action a) noexcept {
    switch (a) {
        case Action::toggle_pause: return "toggle_pause";
        case Action::step: return "step";
        case Action::toggle_ellipsoids: return "toggle_ellipsoids";
        case Action::switch_model: return "switch_model";
        case Action::reset: return "reset";
        case Action::toggle_hud: return "toggle_hud";
        case Action::quit: return "quit";
    }
    return "unknown";
}

/// Input gathered by one `Renderer::poll_events` call (cleared at its start).
struct InputState {
    std::vector<Action> actions;   ///< In the order the user gave them.
    float orbit_dx_px = 0;         ///< Left-button drag since the last poll (already applied to the camera).
    float orbit_dy_px = 0;
    float zoom_steps = 0;          ///< Wheel (+ = closer), already applied to the camera.
    bool window_open = true;       ///< False once the window was closed.

    [[nodiscard]] bool has(Action a) const noexcept {
        for (Action x : actions)
            if (x == a) return true;
        return false;
    }
    void clear() noexcept {
        actions.clear();  // keeps capacity: no allocation per frame
        orbit_dx_px = orbit_dy_px = zoom_steps = 0;
    }
};

}  // namespace drape
