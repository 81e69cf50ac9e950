// Layer-2 particles carried by layer 1 (method §4.2); see weft.hpp.
#include "drape/systems/cloth/weft.hpp"

namespace drape {

void carry_weft(const Fabric& t, std::span<const std::uint32_t> entries, const VectorX& inv_mass, const Matrix3X& x_start,
                Matrix3X& x) {
    for (const std::uint32_t k : entries) {
        const std::uint32_t p = t.weft_particle[k], a = t.weft_left[k], b = t.weft_right[k];
        if (inv_mass[p] == 0) continue;  // pinned in the fitting zone
        const Real s = t.weft_t[k];
        x.col(p) += (1 - s) * (x.col(a) - x_start.col(a)) + s * (x.col(b) - x_start.col(b));
    }
}

}  // namespace drape
