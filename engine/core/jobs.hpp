// Where Drape runs its parallel work. By default on TBB's threads; a game with its own job
// system installs it, as Jolt's JobSystem lets a game run physics on its own workers, and
// the cloth (every garment of a frame, and the parts of a big garment) runs there.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>

namespace drape {

class JobSystem {
public:
    virtual ~JobSystem() = default;
    /// Calls body(k) once for every k in [0, count), on any threads, possibly at the same
    /// time, and returns when all are done. Drape's bodies never wait on each other.
    virtual void parallel_for(std::size_t count, const std::function<void(std::size_t)>& body) = 0;
    /// How many threads may run bodies at once; 1: Drape runs everything on the caller.
    [[nodiscard]] virtual int max_concurrency() const = 0;
};

/// TBB's: one task per index, statically partitioned over the threads TBB has (which
/// tbb::global_control limits).
[[nodiscard]] std::shared_ptr<JobSystem> tbb_job_system();

/// The job system Drape runs on now.
[[nodiscard]] JobSystem& job_system();

/// Installs a game's job system; null goes back to TBB's. Set it between frames, not while a
/// world steps. Results are the same on any job system and any number of threads.
void set_job_system(std::shared_ptr<JobSystem> jobs);

}  // namespace drape
