// The cloth runs on a game's own job system (engine/core/jobs.hpp) with the same results as
// on TBB's.
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <thread>

#include <tbb/global_control.h>

#include "analytic_body.hpp"
#include "drape/engine/core/jobs.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_step.hpp"

namespace drape {
namespace {

/// A game's job system: one std::thread per index, the last index first.
class ThreadPerJob final : public JobSystem {
public:
    std::atomic<int> calls{0}, jobs{0};
    void parallel_for(std::size_t count, const std::function<void(std::size_t)>& body) override {
        ++calls;
        std::vector<std::thread> threads;
        for (std::size_t k = count; k-- > 0;)
            threads.emplace_back([&, k] {
                ++jobs;
                body(k);
            });
        for (auto& t : threads) t.join();
    }
    int max_concurrency() const override { return 4; }
};

Matrix3X dress_after(int frames) {
    Registry registry;
    test::AnalyticBody body(registry);
    const Entity e = *attach_dress(registry, body.character, TubeParams::dress());
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& s = registry.get<GarmentSolver>(e);
    EXPECT_GT(g.fabric->line_bands, 1u) << "the dress is stepped in parts";
    for (int frame = 0; frame < frames; ++frame) {
        body.place(registry, (frame + 1) / 60.0, false, 1.0 / 60.0);
        step_garment(registry, g, s, 1.0 / 60.0, {});
    }
    return g.state.x;
}

TEST(JobSystem, TheClothRunsOnAGamesOwnJobSystemWithTheSameResult) {
    Matrix3X on_tbb;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        on_tbb = dress_after(30);
    }
    auto game = std::make_shared<ThreadPerJob>();
    set_job_system(game);
    const Matrix3X on_game = dress_after(30);
    set_job_system(nullptr);
    EXPECT_GT(game->calls.load(), 0);
    EXPECT_GT(game->jobs.load(), game->calls.load());
    ASSERT_EQ(on_tbb.size(), on_game.size());
    EXPECT_EQ(std::memcmp(on_tbb.data(), on_game.data(), sizeof(Real) * static_cast<std::size_t>(on_tbb.size())), 0);
    EXPECT_EQ(job_system().max_concurrency() > 0, true);
}

}  // namespace
}  // namespace drape
