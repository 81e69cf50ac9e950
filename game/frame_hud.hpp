// The frame budget as it goes: what the heads-up overlay (engine/render/hud.hpp) and the
// window's title show while a scene plays.
//
// After each frame, record() takes from the world every system's time in that frame (the
// profiler's slots, sections included), the whole frame's wall time as the caller measured
// it (present and read-back included), the garments' particles and substeps, the live
// strain (the 99th percentile of the frame's spring strains, the largest over the
// garments, as GarmentWatch samples it) and the contact repair budget hits. It keeps the
// frames of the last second of wall time (at most 2,000) for medians and 95th percentiles.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "drape/engine/render/hud.hpp"

namespace drape {

struct World;

class FrameHud {
public:
    /// Records the frame just stepped. `wall_ms`: the whole frame's wall time, or of the
    /// frame before when this one is not over yet (0: unknown; such frames count one each
    /// towards the window's frame limit and nothing towards its second).
    void record(const World& world, double wall_ms);

    /// The overlay of the frames recorded so far.
    [[nodiscard]] HudOverlay overlay() const;
    /// "Drape  62 fps  16.1 ms" for the window's title.
    [[nodiscard]] std::string title() const;

    /// Frames per second over the window (0 while no wall time is known).
    [[nodiscard]] double fps() const;
    /// Frames in the window.
    [[nodiscard]] std::size_t frames() const noexcept { return m_frames.size(); }

private:
    struct Frame {
        double wall_ms = 0;
        std::vector<double> system_ms;  ///< Per profiler slot.
    };
    std::deque<Frame> m_frames;
    double m_window_wall_ms = 0;
    std::vector<std::string> m_names;
    std::vector<bool> m_sections;
    std::size_t m_garments = 0;
    std::uint64_t m_particles = 0;
    int m_substeps = 0;
    double m_strain_p99 = 0;
    std::uint64_t m_budget_hits = 0;
};

}  // namespace drape
