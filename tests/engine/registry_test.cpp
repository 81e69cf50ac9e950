#include "drape/engine/core/registry.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <set>

namespace drape {
namespace {

struct Position { float x = 0; };
struct Velocity { float v = 0; };
struct Tag {};

TEST(Registry, StaleHandleIsDetectedAfterDestroy) {
    Registry r;
    const Entity a = r.create();
    r.emplace<Position>(a, 1.f);
    r.destroy(a);
    EXPECT_FALSE(r.valid(a));
    EXPECT_EQ(r.try_get<Position>(a), nullptr);

    // The slot is reused with a new generation; the old handle stays stale.
    const Entity b = r.create();
    EXPECT_EQ(b.index, a.index);
    EXPECT_NE(b.generation, a.generation);
    r.emplace<Position>(b, 2.f);
    EXPECT_EQ(r.try_get<Position>(a), nullptr);
    EXPECT_FALSE(r.remove<Position>(a));
    EXPECT_FLOAT_EQ(r.get<Position>(b).x, 2.f);
    r.destroy(a);  // destroying a stale handle does nothing
    EXPECT_TRUE(r.valid(b));
}

TEST(Registry, NullEntityIsNeverValid) {
    Registry r;
    EXPECT_FALSE(r.valid(null_entity));
    EXPECT_FALSE(r.valid(Entity{}));
}

TEST(Registry, EmplaceGetTryGetRemove) {
    Registry r;
    const Entity e = r.create();
    EXPECT_FALSE(r.has<Position>(e));
    r.emplace<Position>(e, 3.f);
    EXPECT_TRUE(r.has<Position>(e));
    EXPECT_FLOAT_EQ(r.get<Position>(e).x, 3.f);
    EXPECT_EQ(r.try_get<Velocity>(e), nullptr);
    EXPECT_TRUE(r.remove<Position>(e));
    EXPECT_FALSE(r.remove<Position>(e));
    EXPECT_EQ(r.count<Position>(), 0u);
    EXPECT_TRUE(r.valid(e));
}

TEST(Registry, RemovalKeepsOtherComponentsIntact) {
    Registry r;
    std::vector<Entity> es;
    for (int i = 0; i < 10; ++i) {
        es.push_back(r.create());
        r.emplace<Position>(es.back(), float(i));
    }
    r.remove<Position>(es[3]);
    r.destroy(es[0]);
    for (int i = 1; i < 10; ++i) {
        if (i == 3) continue;
        EXPECT_FLOAT_EQ(r.get<Position>(es[i]).x, float(i));
    }
    EXPECT_EQ(r.count<Position>(), 8u);
}

TEST(Registry, SharedAssetsAreHeldOnceForManyInstances) {
    struct Asset { int bones = 25; };
    struct Instance { std::shared_ptr<const Asset> asset; };
    Registry r;
    auto asset = std::make_shared<const Asset>();
    for (int i = 0; i < 100; ++i) r.emplace<Instance>(r.create(), asset);
    EXPECT_EQ(asset.use_count(), 101);
}

TEST(View, IteratesEntitiesWithAllComponentsOnly) {
    Registry r;
    std::set<std::uint32_t> expected;
    for (int i = 0; i < 20; ++i) {
        const Entity e = r.create();
        r.emplace<Position>(e, float(i));
        if (i % 3 == 0) {
            r.emplace<Velocity>(e, 1.f);
            expected.insert(e.index);
        }
    }
    std::set<std::uint32_t> seen;
    r.view<Position, Velocity>().each([&](Entity e, Position& p, Velocity& v) {
        EXPECT_TRUE(seen.insert(e.index).second);
        p.x += v.v;
    });
    EXPECT_EQ(seen, expected);
}

TEST(View, IsLedByTheSmallestPool) {
    Registry r;
    for (int i = 0; i < 100; ++i) r.emplace<Position>(r.create());
    const Entity e = r.create();
    r.emplace<Position>(e);
    r.emplace<Velocity>(e);
    EXPECT_EQ((r.view<Position, Velocity>().size_hint()), 1u);
    EXPECT_EQ((r.view<Velocity, Position>().size_hint()), 1u);
}

TEST(View, MissingPoolMeansNothingToDo) {
    Registry r;
    r.emplace<Position>(r.create());
    int calls = 0;
    r.view<Position, Tag>().each([&](Entity, Position&, Tag&) { ++calls; });
    EXPECT_EQ(calls, 0);
    EXPECT_EQ((r.view<Position, Tag>().size_hint()), 0u);
}

TEST(View, RemovingTheVisitedEntityDuringIterationVisitsEveryOtherOnce) {
    Registry r;
    std::vector<Entity> es;
    for (int i = 0; i < 50; ++i) {
        es.push_back(r.create());
        r.emplace<Position>(es.back(), float(i));
        r.emplace<Velocity>(es.back(), 1.f);
    }
    std::multiset<std::uint32_t> visits;
    r.view<Position, Velocity>().each([&](Entity e, Position& p, Velocity&) {
        visits.insert(e.index);
        if (static_cast<int>(p.x) % 2 == 0) r.remove<Velocity>(e);  // drop every even one
        if (static_cast<int>(p.x) % 5 == 0) r.destroy(e);
    });
    EXPECT_EQ(visits.size(), 50u);
    for (const Entity& e : es) EXPECT_EQ(visits.count(e.index), 1u);
    // What remains: odd, not multiple of 5.
    int remaining = 0;
    r.view<Position, Velocity>().each([&](Entity, Position& p, Velocity&) {
        EXPECT_EQ(static_cast<int>(p.x) % 2, 1);
        EXPECT_NE(static_cast<int>(p.x) % 5, 0);
        ++remaining;
    });
    EXPECT_EQ(remaining, 20);
}

TEST(View, AddingToOtherEntitiesDuringIterationDoesNotRevisit) {
    Registry r;
    for (int i = 0; i < 10; ++i) r.emplace<Position>(r.create(), float(i));
    int calls = 0;
    r.view<Position>().each([&](Entity, Position&) {
        ++calls;
        r.emplace<Position>(r.create(), -1.f);  // appended behind the cursor
    });
    EXPECT_EQ(calls, 10);
    EXPECT_EQ(r.count<Position>(), 20u);
}

}  // namespace
}  // namespace drape
