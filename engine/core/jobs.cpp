#include "drape/engine/core/jobs.hpp"

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

namespace drape {

namespace {

class TbbJobSystem final : public JobSystem {
public:
    void parallel_for(std::size_t count, const std::function<void(std::size_t)>& body) override {
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(0, count, 1),
            [&](const tbb::blocked_range<std::size_t>& r) {
                for (std::size_t k = r.begin(); k != r.end(); ++k) body(k);
            },
            tbb::static_partitioner());
    }
    int max_concurrency() const override {
        return static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
    }
};

std::shared_ptr<JobSystem>& installed() {
    static std::shared_ptr<JobSystem> jobs = tbb_job_system();
    return jobs;
}

}  // namespace

std::shared_ptr<JobSystem> tbb_job_system() { return std::make_shared<TbbJobSystem>(); }

JobSystem& job_system() { return *installed(); }

void set_job_system(std::shared_ptr<JobSystem> jobs) { installed() = jobs ? std::move(jobs) : tbb_job_system(); }

}  // namespace drape
