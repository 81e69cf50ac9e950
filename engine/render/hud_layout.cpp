// Overlay layout, in units of the scale (1 unit = 1 px at 640x360, 2 px at 1280x720):
// a margin of 6 from the corner, a padding of 4 inside the panel, lines 9 apart (the
// font's capitals are 7 tall). Under the text lines, a header row,
// then per row: the name, three right-aligned numbers (last, p50, p95 in ms), and a bar
// 48 long where the full length is HudOverlay::full_bar_ms: the median as a pale bar, the
// last frame as a bright one over it, the 95th percentile as a tick.
#include "drape/engine/render/hud_layout.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Wuseless-cast"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <stb/stb_easy_font.h>
#pragma GCC diagnostic pop

namespace drape::render_detail {

namespace {

constexpr float margin = 6, padding = 4, line = 9, bar_length = 48, column_gap = 5;

struct Color {
    float r, g, b, a;
};
constexpr Color panel_color{0.05f, 0.06f, 0.08f, 0.62f};
constexpr Color text_color{0.96f, 0.96f, 0.94f, 1.0f};
constexpr Color section_color{0.72f, 0.76f, 0.80f, 1.0f};
constexpr Color header_color{0.60f, 0.78f, 0.95f, 1.0f};
constexpr Color median_color{0.55f, 0.60f, 0.66f, 0.85f};
constexpr Color last_color{1.00f, 0.66f, 0.22f, 1.0f};
constexpr Color p95_color{1.00f, 0.30f, 0.30f, 1.0f};
constexpr Color track_color{1.0f, 1.0f, 1.0f, 0.12f};

/// Draws into `out`, mapping layout units to pixels.
struct Painter {
    std::vector<HudVertex>& out;
    float scale, x0, y0;

    void rect(float x, float y, float w, float h, Color c) const {
        if (w <= 0 || h <= 0) return;
        const float ax = x0 + x * scale, ay = y0 + y * scale, bx = ax + w * scale, by = ay + h * scale;
        for (auto [px, py] : {std::pair{ax, ay}, {bx, ay}, {bx, by}, {ax, ay}, {bx, by}, {ax, by}})
            out.push_back({px, py, c.r, c.g, c.b, c.a});
    }
    void text(float x, float y, const std::string& s, Color c) const {
        if (s.empty()) return;
        std::string copy = s;
        static thread_local std::vector<char> quads;  // stb: 4 vertices of 16 bytes per quad
        quads.resize(std::max<std::size_t>(4096, copy.size() * 270 * 4));
        unsigned char rgba[4] = {255, 255, 255, 255};
        const int count = stb_easy_font_print(0, 0, copy.data(), rgba, quads.data(), int(quads.size()));
        for (int q = 0; q < count; ++q) {
            float corner[4][2];
            for (int k = 0; k < 4; ++k) {
                float xy[2];
                std::memcpy(xy, quads.data() + (q * 4 + k) * 16, sizeof xy);
                corner[k][0] = x0 + (x + xy[0]) * scale;
                corner[k][1] = y0 + (y + xy[1]) * scale;
            }
            for (int k : {0, 1, 2, 0, 2, 3}) out.push_back({corner[k][0], corner[k][1], c.r, c.g, c.b, c.a});
        }
    }
};

float text_width(const std::string& s) {
    std::string copy = s;
    return float(stb_easy_font_width(copy.data()));
}

std::string milliseconds(double ms) {
    char buffer[32];
    if (!std::isfinite(ms) || ms < 0) return "-";
    std::snprintf(buffer, sizeof buffer, ms < 10 ? "%.2f" : ms < 100 ? "%.1f" : "%.0f", ms);
    return buffer;
}

}  // namespace

int hud_scale(int frame_width, int frame_height) noexcept { return std::max(1, std::min(frame_width / 640, frame_height / 360)); }

HudExtent layout_hud(const HudOverlay& hud, int frame_width, int frame_height, std::vector<HudVertex>& out) {
    out.clear();
    const float scale = float(hud_scale(frame_width, frame_height));
    Painter paint{out, scale, margin * scale, margin * scale};

    // Column widths, in layout units.
    float name_width = text_width("system");
    for (const HudBar& bar : hud.bars) name_width = std::max(name_width, text_width((bar.section ? "  " : "") + bar.name));
    const float number_width = text_width("00.00");
    const float numbers_x = name_width + column_gap;
    const float bar_x = numbers_x + 3 * (number_width + column_gap);
    float width = hud.bars.empty() ? 0 : bar_x + bar_length;
    for (const std::string& l : hud.lines) width = std::max(width, text_width(l));
    const float rows = float(hud.lines.size()) + (hud.bars.empty() ? 0 : float(hud.bars.size()) + 1);
    const float height = rows * line;

    paint.rect(0, 0, width + 2 * padding, height + 2 * padding - 2, panel_color);
    float y = padding;
    for (const std::string& l : hud.lines) {
        paint.text(padding, y, l, text_color);
        y += line;
    }
    if (!hud.bars.empty()) {
        const auto right = [&](float column, const std::string& s, float row_y, Color c) {
            paint.text(padding + numbers_x + column * (number_width + column_gap) + number_width - text_width(s), row_y, s, c);
        };
        paint.text(padding, y, "system", header_color);
        right(0, "last", y, header_color);
        right(1, "p50", y, header_color);
        right(2, "p95", y, header_color);
        char scale_label[32];
        std::snprintf(scale_label, sizeof scale_label, "0-%g ms", hud.full_bar_ms);
        paint.text(padding + bar_x, y, scale_label, header_color);
        y += line;
        const double full = hud.full_bar_ms > 0 ? hud.full_bar_ms : 1;
        const auto length = [&](double ms) { return float(std::clamp(ms / full, 0.0, 1.0)) * bar_length; };
        for (const HudBar& bar : hud.bars) {
            const Color name_color = bar.section ? section_color : text_color;
            paint.text(padding, y, (bar.section ? "  " : "") + bar.name, name_color);
            right(0, milliseconds(bar.last_ms), y, name_color);
            right(1, milliseconds(bar.p50_ms), y, name_color);
            right(2, milliseconds(bar.p95_ms), y, name_color);
            const float bx = padding + bar_x, by = y + 1;
            paint.rect(bx, by, bar_length, 6, track_color);
            paint.rect(bx, by, length(bar.p50_ms), 6, median_color);
            paint.rect(bx, by + 2, length(bar.last_ms), 2, last_color);
            paint.rect(bx + std::max(0.0f, length(bar.p95_ms) - 1), by, 1, 6, p95_color);
            y += line;
        }
    }
    return {int(std::ceil((width + 2 * padding) * scale)), int(std::ceil((height + 2 * padding) * scale))};
}

}  // namespace drape::render_detail
