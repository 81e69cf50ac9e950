// Lays a HudOverlay out as coloured triangles in pixels (top-left origin). Internal to
// the renderer; a free function so that the layout is built without a GL context.
#pragma once

#include <vector>

#include "drape/engine/render/hud.hpp"

namespace drape::render_detail {

/// One overlay vertex: position in pixels from the frame's top-left corner, RGBA 0..1
/// (not premultiplied).
struct HudVertex {
    float x, y;
    float r, g, b, a;
};

/// The overlay's scale: whole units of a 640 x 360 frame that fit in the frame (1 at
/// 640x360 and 960x540, 2 at 1280x720, 3 at 1920x1080), at least 1. Rounded down, so that the
/// panel stays within the top-left corner and off the character at the frame's centre.
[[nodiscard]] int hud_scale(int frame_width, int frame_height) noexcept;

/// The panel's size in pixels, its margin from the corner not included.
struct HudExtent {
    int width = 0, height = 0;
};
/// Writes the overlay's triangles (three vertices each) into `out` (cleared first) for a
/// frame `frame_width` x `frame_height` px, and returns the panel's size.
HudExtent layout_hud(const HudOverlay& hud, int frame_width, int frame_height, std::vector<HudVertex>& out);

}  // namespace drape::render_detail
