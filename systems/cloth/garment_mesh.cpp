#include "drape/systems/cloth/garment_mesh.hpp"

#include "drape/components/garment.hpp"
#include "drape/engine/core/mesh_normals.hpp"

namespace drape {

Result<void> read_garment_mesh(const Registry& registry, Entity garment, GarmentMesh& out) {
    if (!registry.valid(garment)) return fail("read_garment_mesh: the entity does not exist (destroyed or null)");
    const Garment* g = registry.try_get<Garment>(garment);
    if (!g) return fail("read_garment_mesh: the entity has no Garment component");
    if (!g->fabric || g->state.x.cols() == 0) return fail("read_garment_mesh: the garment has not been built (attach_skirt, attach_dress)");
    out.positions = g->state.x;
    out.triangles.assign(g->fabric->triangles.begin(), g->fabric->triangles.end());
    vertex_normals(out.positions, out.triangles, out.normals);
    out.color = g->config.color;
    return {};
}

}  // namespace drape
