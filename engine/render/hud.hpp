// The heads-up overlay: the frame budget drawn over a frame (Renderer::draw_hud).
//
// Plain data the caller fills each frame (game/frame_hud.hpp fills it from the profiler and
// the garments); the renderer lays it out in the frame's top-left corner, scaled with the
// frame's height (a whole multiple of 360 px: 1 at 640x360, 2 at 1280x720), on a
// semi-transparent panel: the text lines, then one row per system with its name, its
// last, median and 95th-percentile times and a bar of each. Text is stb_easy_font's.
#pragma once

#include <string>
#include <vector>

namespace drape {

/// One system's (or timed section's) row of the overlay.
struct HudBar {
    std::string name;
    bool section = false;  ///< A section of the system above it: indented, dimmer.
    double last_ms = 0;    ///< In the last frame.
    double p50_ms = 0;     ///< Median over the recent frames.
    double p95_ms = 0;     ///< 95th percentile over the recent frames.
};

/// What the overlay shows.
struct HudOverlay {
    std::vector<std::string> lines;  ///< Text above the bars, one line each (ASCII).
    std::vector<HudBar> bars;        ///< In the order listed.
    double full_bar_ms = 16.7;       ///< The time a full bar stands for.
};

}  // namespace drape
