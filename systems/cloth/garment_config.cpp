// Configuration changes; see garment_config.hpp.
#include "drape/systems/cloth/garment_config.hpp"

#include <algorithm>
#include <string>

#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_solver.hpp"

namespace drape {
namespace {

void drop_caches(Registry& registry, Entity garment) {
    if (GarmentSolver* s = registry.try_get<GarmentSolver>(garment)) invalidate(*s);
}

}  // namespace

bool set_garment_model(Registry& registry, Entity garment, ClothModel model) {
    Garment* g = registry.try_get<Garment>(garment);
    if (g == nullptr) return false;
    g->config.model = model;
    drop_caches(registry, garment);
    return true;
}

Result<void> set_garment_material(Registry& registry, Entity garment, const ClothMaterial& material) {
    Garment* g = registry.try_get<Garment>(garment);
    if (g == nullptr) return fail("set_garment_material: entity " + std::to_string(garment.index) + " has no garment");
    if (auto ok = validate(material, "material"); !ok) return ok;
    g->config.material = material;
    drop_caches(registry, garment);
    return {};
}

Result<void> set_garment_state(Registry& registry, Entity garment, const Matrix3X& x, const Matrix3X& v) {
    Garment* g = registry.try_get<Garment>(garment);
    if (g == nullptr) return fail("set_garment_state: entity " + std::to_string(garment.index) + " has no garment");
    const Eigen::Index n = g->state.x.cols();
    if (x.cols() != n || v.cols() != n)
        return fail("set_garment_state: " + std::to_string(x.cols()) + " positions and " + std::to_string(v.cols()) +
                    " velocities for " + std::to_string(n) + " particles");
    if (!x.allFinite() || !v.allFinite()) return fail("set_garment_state: non-finite positions or velocities");
    g->state.x = x;
    g->state.v = v;
    if (GarmentSolver* s = registry.try_get<GarmentSolver>(garment)) {
        // Last substep's contacts and the lists' references were of other places.
        std::fill(s->last_collided.begin(), s->last_collided.end(), 0);
        s->lists.valid = false;
    }
    return {};
}

}  // namespace drape
