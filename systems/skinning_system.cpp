// Skinning system: see skinning_system.hpp.
#include "systems/skinning_system.hpp"

#include "components/skeleton.hpp"
#include "components/skinned_mesh.hpp"
#include "components/transform.hpp"
#include "systems/character/pose.hpp"

namespace drape {

System make_skinning_system() {
    System s;
    s.name = "skinning";
    s.phase = Phase::skinning;
    s.reads = components<Skeleton>();
    s.writes = components<SkinnedMesh>();
    s.optional_reads = components<Transform>();
    s.run = [](Registry& registry, const FrameContext&) {
        registry.view<Skeleton, SkinnedMesh>().each([&](Entity e, Skeleton& skeleton, SkinnedMesh& skin) {
            if (!skin.mesh || skeleton.skinning.size() != skeleton.asset->size()) return;
            const Transform* t = registry.try_get<Transform>(e);
            skin_mesh(*skin.mesh, skeleton.skinning, t ? t->matrix() : Affine3::Identity(), skin.positions, skin.normals);
        });
    };
    return s;
}

}  // namespace drape
