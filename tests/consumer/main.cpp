// Links against the installed Drape package and runs one scheduled frame.
#include <cstdio>

#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"

struct Spin {
    float angle = 0;
};

int main() {
    drape::Registry registry;
    drape::Scheduler scheduler;
    registry.emplace<Spin>(registry.create());
    scheduler.add({"spin", drape::Phase::simulation, {}, drape::components<Spin>(), {},
                   [](drape::Registry& r, const drape::FrameContext& c) {
                       r.view<Spin>().each([&](drape::Entity, Spin& s) { s.angle += float(c.fixed_dt_s); });
                   }});
    auto report = scheduler.tick(registry, 1.0 / 60.0);
    if (!report || report->steps != 1) return 1;
    std::puts("consumer: ok");
    return 0;
}
