// Garment quality after a frame; conventions in garment_quality.hpp.
#include "drape/systems/cloth/garment_quality.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "drape/systems/cloth/body.hpp"
#include "drape/systems/cloth/collision.hpp"

namespace drape {

void StrainHistogram::add(Real strain) noexcept {
    const Real s = std::isfinite(strain) ? std::max(strain, Real(0)) : Real(bins) * bin;
    const std::size_t k = std::min(bins - 1, static_cast<std::size_t>(s / bin));
    ++m_counts[k];
    ++m_samples;
}

Real StrainHistogram::percentile(double q) const noexcept {
    if (m_samples == 0) return 0;
    const auto wanted = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(m_samples)));
    std::uint64_t seen = 0;
    for (std::size_t k = 0; k < bins; ++k) {
        seen += m_counts[k];
        if (seen >= wanted) return Real(k + 1) * bin;
    }
    return Real(bins) * bin;
}

GarmentQuality measure_garment(const Garment& g, std::span<const EllipsoidFrame> frames, StrainHistogram* histogram) {
    GarmentQuality q;
    if (!g.fabric) return q;
    const Fabric& t = *g.fabric;
    const Matrix3X& x = g.state.x;
    const VectorX& w = g.state.inv_mass;
    q.nonfinite = static_cast<std::uint64_t>((!x.array().isFinite()).count() + (!g.state.v.array().isFinite()).count());

    std::vector<Real> strains;
    strains.reserve(t.warp1.size() + t.warp2.size() + t.weft.size());
    for (const SpringPhase* phase : {&t.warp1, &t.warp2, &t.weft})
        for (std::size_t s = 0; s < phase->size(); ++s) {
            const std::uint32_t a = phase->a[s], b = phase->b[s];
            if (w[a] == 0 && w[b] == 0) continue;
            const Real ratio = (x.col(b) - x.col(a)).norm() / phase->rest_m[s];
            const Real strain = std::isfinite(ratio) ? std::max(Real(0), ratio - 1) : std::numeric_limits<Real>::infinity();
            strains.push_back(strain);
            if (histogram) histogram->add(strain);
        }
    q.springs = strains.size();
    if (!strains.empty()) {
        const std::size_t k = std::min(strains.size() - 1, static_cast<std::size_t>(std::ceil(0.99 * double(strains.size()))) - 1);
        std::nth_element(strains.begin(), strains.begin() + static_cast<std::ptrdiff_t>(k), strains.end());
        q.strain_p99 = strains[k];
        q.strain_max = *std::max_element(strains.begin(), strains.end());
    }

    Real highest_pin = -std::numeric_limits<Real>::infinity();
    for (Eigen::Index i = 0; i < x.cols(); ++i)
        if (w[i] == 0) highest_pin = std::max(highest_pin, x(1, i));
    for (Eigen::Index i = 0; i < x.cols(); ++i)
        if (w[i] != 0 && std::isfinite(highest_pin) && std::isfinite(x(1, i)))
            q.rise_above_pins_m = std::max(q.rise_above_pins_m, x(1, i) - highest_pin);
    // Depths: each ellipsoid against the particles in its bounding box only; past its give
    // where it gives (collision.hpp), the depth within the give kept apart.
    for (std::size_t e = 0; e < frames.size(); ++e) {
        const EllipsoidFrame& f = frames[e];
        if (!f.active) continue;
        const Vec3 half = f.rotation.cwiseAbs() * f.radii_m;
        const Vec3 low = f.center - half, high = f.center + half;
        for (Eigen::Index i = 0; i < x.cols(); ++i) {
            const Vec3 p = x.col(i);
            if ((p.array() < low.array()).any() || (p.array() > high.array()).any()) continue;  // NaN too: counted above
            const Real depth = penetration_depth(f, p);
            if (depth <= 0) continue;
            const Real past = f.give_m > 0 ? depth_past_give(frames, e, p) : depth;
            Real& worst = w[i] == 0 ? q.pins_inside_m : q.penetration_m;
            worst = std::max(worst, past);
            if (w[i] != 0) q.within_give_m = std::max(q.within_give_m, depth - past);
        }
    }
    return q;
}

GarmentQuality measure_garment(const Registry& registry, const Garment& garment, StrainHistogram* histogram) {
    std::vector<EllipsoidFrame> frames;
    update_frames(registry, garment.body, frames, 1);
    return measure_garment(garment, frames, histogram);
}

}  // namespace drape
