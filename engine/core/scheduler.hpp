// The per-frame schedule: fixed phases, a fixed simulation step, per-system timing.
//
// Order of one `tick(frame_dt)` (method §1):
//   input                       once per frame
//   repeat for each fixed step taken from the accumulator:
//     animation, skinning       once per step (colliders follow their bones in skinning)
//     simulation                once per step (a solver that substeps owns its loop)
//   render                      once per frame
// Within a phase, systems run in the order they were added.
//
// Skipping: a system runs only while every component it reads or writes has at least one
// instance in the registry ("leave out what a scene does not need"); otherwise the skip is
// counted in the profile. `optional_reads` are declared but do not gate.
//
// Hitches: the accumulator takes frame_dt * time_scale. At most `max_steps_per_frame`
// steps run per tick; simulated time beyond that is dropped and reported in the
// `FrameReport`, so a 0.5 s hitch neither freezes the game (no spiral of death) nor hands
// the cloth a 0.5 s step: the world runs slow for that frame. A negative or non-finite
// frame time is rejected with an error and nothing runs.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/profiler.hpp"
#include "drape/engine/core/registry.hpp"

namespace drape {

enum class Phase : std::uint8_t { input, animation, skinning, simulation, render };
inline constexpr std::size_t phase_count = 5;
[[nodiscard]] const char* phase_name(Phase p) noexcept;

/// What a system knows about the current call.
struct FrameContext {
    std::uint64_t frame = 0;      ///< Frames ticked before this one.
    double frame_dt_s = 0;        ///< Wall-clock frame time given to tick().
    double fixed_dt_s = 0;        ///< Simulated time per fixed step.
    double time_s = 0;            ///< Simulated time at the start of this step.
    int step = 0;                 ///< Index of the fixed step within this frame.
    int steps = 0;                ///< Fixed steps taken this frame (known once stepping starts).
    FrameProfiler* profiler = nullptr;  ///< The scheduler's, for systems that time sections of their own.
};

using SystemFn = std::function<void(Registry&, const FrameContext&)>;

/// A system: a name, a phase, declared access and one run function.
struct System {
    std::string name;
    Phase phase = Phase::simulation;
    std::vector<ComponentId> reads;           ///< Read-only; gates the run.
    std::vector<ComponentId> writes;          ///< Written; gates the run.
    std::vector<ComponentId> optional_reads;  ///< Read when present; does not gate.
    SystemFn run;
};

/// Component ids of a list of types, for System::reads/writes.
template <class... Ts>
[[nodiscard]] std::vector<ComponentId> components() { return {component_id<Ts>()...}; }

struct SchedulerSettings {
    double fixed_dt_s = 1.0 / 60.0;  ///< Simulated time per fixed step.
    int max_steps_per_frame = 4;     ///< Cap; time beyond it is dropped (see hitches above).
    double time_scale = 1.0;         ///< Simulated seconds per wall-clock second.
};

/// Checks settings; the error names the field.
[[nodiscard]] Result<void> validate(const SchedulerSettings& s);

/// What one tick did.
struct FrameReport {
    int steps = 0;           ///< Fixed steps simulated.
    double dropped_s = 0;    ///< Simulated time dropped because of the step cap.
};

class Scheduler {
public:
    /// `settings` must pass validate(); use create() to check user-provided ones.
    explicit Scheduler(SchedulerSettings settings = {});
    [[nodiscard]] static Result<Scheduler> create(SchedulerSettings settings);

    /// Adds a system; returns its profiler slot.
    std::uint32_t add(System system);

    /// Runs one frame. Errors only on a bad frame time; then nothing runs.
    Result<FrameReport> tick(Registry& registry, double frame_dt_s);

    /// Runs only the systems of one phase once, as tick() would (gating, timing).
    void run_phase(Registry& registry, Phase phase, const FrameContext& context);

    [[nodiscard]] const SchedulerSettings& settings() const noexcept { return m_settings; }
    [[nodiscard]] Result<void> set_time_scale(double scale);
    [[nodiscard]] FrameProfiler& profiler() noexcept { return m_profiler; }
    [[nodiscard]] const FrameProfiler& profiler() const noexcept { return m_profiler; }
    [[nodiscard]] double time_s() const noexcept { return m_time_s; }
    [[nodiscard]] std::uint64_t frame() const noexcept { return m_frame; }
    [[nodiscard]] double total_dropped_s() const noexcept { return m_total_dropped_s; }
    /// Names of the systems of a phase, in run order.
    [[nodiscard]] std::vector<std::string> system_names(Phase phase) const;

private:
    struct Entry {
        System system;
        std::uint32_t slot;
    };
    [[nodiscard]] static bool present(const Registry& registry, const System& system);

    SchedulerSettings m_settings;
    std::array<std::vector<Entry>, phase_count> m_phases;
    FrameProfiler m_profiler;
    double m_accumulator_s = 0;
    double m_time_s = 0;
    double m_total_dropped_s = 0;
    std::uint64_t m_frame = 0;
};

}  // namespace drape
