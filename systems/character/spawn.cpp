// Spawning characters: see spawn.hpp.
#include "drape/systems/character/spawn.hpp"

#include <cmath>

#include "drape/components/animation_player.hpp"
#include "drape/components/body_landmarks.hpp"
#include "drape/components/character.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/engine/assets/character_import.hpp"
#include "drape/systems/character/animation.hpp"
#include "drape/systems/character/colliders.hpp"
#include "drape/systems/character/ellipsoid_fit.hpp"
#include "drape/systems/character/pose.hpp"

namespace drape {

Result<Entity> spawn_character(Registry& registry, std::shared_ptr<const CharacterAsset> asset,
                               const CharacterBody& body, const SpawnOptions& options) {
    if (!asset || !asset->skeleton || !asset->mesh) return fail("spawn_character: no character asset");
    const std::string at = asset->source.string() + ": ";
    const Transform& t = options.transform;
    if (!t.position.allFinite() || !t.rotation.coeffs().allFinite() || t.rotation.norm() < 1e-6f)
        return fail(at + "transform: position and rotation must be finite");
    if (!(std::isfinite(t.scale) && t.scale > 0)) return fail(at + "transform.scale: must be > 0");
    if (!std::isfinite(options.speed)) return fail(at + "speed: must be finite");
    if (!std::isfinite(options.start_time_s)) return fail(at + "start_time_s: must be finite");

    std::shared_ptr<const AnimationClip> clip;
    if (!options.clip.empty()) {
        auto index = find_clip(*asset, options.clip);
        if (!index) return std::unexpected(index.error());
        clip = asset->clips[*index];
    } else if (const auto choice = choose_default_clip(*asset)) {
        clip = asset->clips[choice->index];
    }
    const int bones = static_cast<int>(asset->skeleton->size());
    for (std::size_t i = 0; i < body.ellipsoids.size(); ++i)  // a body fitted to another character
        if (body.ellipsoids[i].bone < 0 || body.ellipsoids[i].bone >= bones)
            return fail(at + "body.ellipsoids[" + std::to_string(i) + "].bone: out of range");
    for (std::size_t i = 0; i < options.collider_overrides.size(); ++i) {
        const EllipsoidShape& s = options.collider_overrides[i];
        const std::string field = at + "colliders[" + std::to_string(i) + "]";
        if (s.bone < 0 || s.bone >= bones) return fail(field + ".bone: out of range");
        if (!s.center.allFinite() || !s.rotation.coeffs().allFinite()) return fail(field + ": must be finite");
        if (!(s.radii_m.minCoeff() > 0) || !s.radii_m.allFinite()) return fail(field + ".radii_m: must be > 0");
    }

    const Entity e = registry.create();
    registry.emplace<Character>(e, Character{asset->name, asset, body.landmarks ? body.landmarks->height_m : asset->height_m});
    if (body.landmarks) registry.emplace<BodyLandmarks>(e, *body.landmarks);
    Transform& transform = registry.emplace<Transform>(e, options.transform);
    transform.rotation.normalize();
    AnimationPlayer& player = registry.emplace<AnimationPlayer>(e);
    player.clip = clip;
    player.speed = options.speed;
    player.loop = options.loop.value_or(clip && clip_loops(*clip));
    player.in_place = options.in_place;
    player.time_s = clip ? wrap_clip_time(options.start_time_s, clip->duration_s, player.loop).time_s : 0;
    Skeleton& skeleton = registry.emplace<Skeleton>(e);
    skeleton.asset = asset->skeleton;
    advance_animation(player, skeleton, &transform, 0);  // pose at the start time
    SkinnedMesh& skin = registry.emplace<SkinnedMesh>(e);
    skin.mesh = asset->mesh;
    skin_mesh(*skin.mesh, skeleton.skinning, transform.matrix(), skin.positions, skin.normals);  // drawable at once
    skin.skinned_vertices = static_cast<std::uint64_t>(skin.positions.cols());

    for (const EllipsoidShape& s : apply_overrides(body.ellipsoids, options.collider_overrides,
                                                   options.replace_fitted_colliders)) {
        const Entity c = registry.create();
        EllipsoidCollider collider;
        collider.character = e;
        collider.bone = s.bone;
        collider.center = s.center;
        collider.rotation = s.rotation;
        collider.radii_m = s.radii_m;
        collider.region = s.region;
        collider.give_m = s.give_m;
        // World transform valid at once (placed, so a garment can be attached before the
        // first step); velocities start with the first step.
        update_collider(collider, registry.get<Skeleton>(e), &registry.get<Transform>(e), 0);
        collider.initialised = false;
        collider.updates = 0;
        registry.emplace<EllipsoidCollider>(c, collider);
    }
    return e;
}

std::vector<Entity> colliders_of(Registry& registry, Entity character) {
    std::vector<Entity> out;
    registry.view<EllipsoidCollider>().each([&](Entity e, EllipsoidCollider& c) {
        if (c.character == character) out.push_back(e);
    });
    std::reverse(out.begin(), out.end());  // creation order
    return out;
}

void despawn_character(Registry& registry, Entity character) {
    for (Entity c : colliders_of(registry, character)) registry.destroy(c);
    registry.destroy(character);
}

}  // namespace drape
