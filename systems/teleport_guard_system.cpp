// Teleport guard: see teleport_guard_system.hpp.
#include "drape/systems/teleport_guard_system.hpp"

#include <algorithm>
#include <utility>
#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/transform.hpp"
#include "drape/systems/cloth/garment_builder.hpp"

namespace drape {

void forget_collider_motion(Registry& registry, Entity character) {
    registry.view<EllipsoidCollider>().each([&](Entity, EllipsoidCollider& c) {
        if (c.character != character) return;
        c.previous_world = c.world;
        c.velocity_m_s.setZero();
        c.acceleration_m_s2.setZero();
        c.angular_velocity_rad_s.setZero();
        c.updates = std::min<std::uint8_t>(c.updates, 1);  // the next step's velocity, but no acceleration from zero
    });
}

System make_teleport_guard_system(double threshold_m, std::shared_ptr<TeleportLog> log) {
    struct Last {
        Entity entity;
        Vec3 root;
    };
    auto last = std::make_shared<std::vector<Last>>();
    System s;
    s.name = "teleport_guard";
    s.phase = Phase::skinning;
    s.reads = components<Transform, Skeleton>();
    s.writes = components<Garment>();
    s.optional_reads = components<EllipsoidCollider>();
    s.run = [threshold_m, log, last](Registry& registry, const FrameContext&) {
        std::vector<Entity> jumped;
        std::vector<Last> now;
        registry.view<Transform, Skeleton>().each([&](Entity e, Transform& t, Skeleton& skeleton) {
            const Vec3 local = skeleton.global.empty() ? Vec3::Zero() : Vec3(skeleton.global[0].translation());
            const Vec3 root = t.matrix() * local;
            now.push_back({e, root});
            for (const Last& l : *last)
                if (l.entity == e && (root - l.root).norm() > threshold_m) jumped.push_back(e);
        });
        *last = std::move(now);
        if (jumped.empty()) return;
        for (Entity character : jumped) {
            ++log->teleports;
            // The jump is no motion: the colliders must not carry its velocity into the cloth.
            forget_collider_motion(registry, character);
            std::vector<Entity> worn;
            registry.view<Garment>().each([&](Entity g, Garment& garment) {
                if (garment.body.character == character) worn.push_back(g);
            });
            for (Entity g : worn) {
                reset_garment(registry, g);
                ++log->resets;
            }
        }
    };
    return s;
}

}  // namespace drape
