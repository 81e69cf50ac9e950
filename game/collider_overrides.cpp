// Collider overrides; see collider_overrides.hpp.
#include "drape/game/collider_overrides.hpp"

#include <string>
#include <vector>

#include "drape/components/ellipsoid_collider.hpp"
#include "drape/systems/character/spawn.hpp"

namespace drape {

namespace {

constexpr Real degrees = Real(3.14159265358979323846 / 180.0);

Quat euler_deg(const Vec3& deg) {
    return Quat(Eigen::AngleAxis<Real>(deg.y() * degrees, Vec3::UnitY()) * Eigen::AngleAxis<Real>(deg.x() * degrees, Vec3::UnitX()) *
                Eigen::AngleAxis<Real>(deg.z() * degrees, Vec3::UnitZ()));
}

}  // namespace

Result<void> apply_collider_overrides(Registry& registry, Entity character, std::size_t index,
                                      std::span<const ColliderOverride> overrides, const CharacterAsset& asset) {
    for (std::size_t k = 0; k < overrides.size(); ++k) {
        const ColliderOverride& o = overrides[k];
        if (o.character != static_cast<int>(index)) continue;
        const std::string field = "colliders[" + std::to_string(k) + "].bone";
        const int bone = asset.skeleton ? asset.skeleton->find(o.bone) : -1;
        if (bone < 0) {
            std::string bones;
            if (asset.skeleton)
                for (std::size_t b = 0; b < asset.skeleton->bone_names.size() && b < 12; ++b)
                    bones += (b ? ", " : "") + asset.skeleton->bone_names[b];
            return fail(located(o.where, field, "no bone \"" + o.bone + "\" in " + asset.source.string() + " (bones: " + bones +
                                                    (asset.skeleton && asset.skeleton->size() > 12 ? ", ..." : "") + ")"));
        }
        std::vector<Entity> on_bone;
        for (Entity e : colliders_of(registry, character))
            if (const auto* c = registry.try_get<EllipsoidCollider>(e); c && c->bone == bone) on_bone.push_back(e);
        if (o.remove) {
            if (on_bone.empty()) return fail(located(o.where, field, "bone \"" + o.bone + "\" has no fitted ellipsoid to remove"));
            for (Entity e : on_bone) registry.destroy(e);
            continue;
        }
        if (on_bone.empty()) {  // a new ellipsoid on this bone
            const Entity e = registry.create();
            EllipsoidCollider& c = registry.emplace<EllipsoidCollider>(e);
            c.character = character;
            c.bone = bone;
            on_bone.push_back(e);
        }
        for (Entity e : on_bone) {
            EllipsoidCollider& c = registry.get<EllipsoidCollider>(e);
            if (o.center_m) c.center = *o.center_m;
            if (o.radii_m) c.radii_m = *o.radii_m;
            if (o.rotation_deg) c.rotation = euler_deg(*o.rotation_deg);
            if (o.give_m) c.give_m = *o.give_m;
            c.initialised = false;
            c.placed = false;  // its world transform is the old shape's until the next update
        }
    }
    return {};
}

}  // namespace drape
