// Skinning system: see skinning_system.hpp.
#include "drape/systems/skinning_system.hpp"

#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/components/transform.hpp"
#include "drape/systems/character/pose.hpp"

namespace drape {
namespace {

void skin_one(Registry& registry, Entity e) {
    Skeleton* skeleton = registry.try_get<Skeleton>(e);
    SkinnedMesh* skin = registry.try_get<SkinnedMesh>(e);
    if (!skeleton || !skin || !skin->mesh || !skeleton->asset || skeleton->skinning.size() != skeleton->asset->size()) return;
    const Transform* t = registry.try_get<Transform>(e);
    skin_mesh(*skin->mesh, skeleton->skinning, t ? t->matrix() : Affine3::Identity(), skin->positions, skin->normals);
    skin->skinned_vertices += static_cast<std::uint64_t>(skin->positions.cols());
}

// Characters are independent: each task reads one Skeleton and writes one SkinnedMesh.
void skin_all(Registry& registry, std::vector<Entity>& entities) {
    entities.clear();
    registry.view<Skeleton, SkinnedMesh>().each([&](Entity e, Skeleton&, SkinnedMesh&) { entities.push_back(e); });
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, entities.size()), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i < r.end(); ++i) skin_one(registry, entities[i]);
    });
}

}  // namespace

void skin_characters(Registry& registry) {
    std::vector<Entity> entities;
    skin_all(registry, entities);
}

System make_skinning_system() {
    System s;
    s.name = "skinning";
    s.phase = Phase::render;
    s.reads = components<Skeleton>();
    s.writes = components<SkinnedMesh>();
    s.optional_reads = components<Transform>();
    s.run = [entities = std::vector<Entity>{}](Registry& registry, const FrameContext&) mutable { skin_all(registry, entities); };
    return s;
}

}  // namespace drape
