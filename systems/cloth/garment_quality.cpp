// Garment quality after a frame; conventions in garment_quality.hpp.
#include "drape/systems/cloth/garment_quality.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "drape/systems/cloth/body.hpp"
#include "drape/systems/cloth/collision.hpp"

namespace drape {

namespace {

std::size_t histogram_bin(Real strain) noexcept {
    const Real s = std::isfinite(strain) ? std::max(strain, Real(0)) : Real(StrainHistogram::bins) * StrainHistogram::bin;
    return std::min(StrainHistogram::bins - 1, static_cast<std::size_t>(s / StrainHistogram::bin));
}

}  // namespace

void StrainHistogram::add(Real strain) noexcept {
    ++m_counts[histogram_bin(strain)];
    ++m_samples;
}

void StrainHistogram::add(std::span<const Real> strains) noexcept {
    for (const Real strain : strains) ++m_counts[histogram_bin(strain)];
    m_samples += strains.size();
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

Vec3 body_up(const Garment& g, std::span<const EllipsoidFrame> frames) {
    const GarmentBody& b = g.body;
    const VectorX& w = g.state.inv_mass;
    if (b.anchor < 0 || static_cast<std::size_t>(b.anchor) >= frames.size() || !frames[static_cast<std::size_t>(b.anchor)].active ||
        b.rest_local.cols() != w.size())
        return Vec3::UnitY();
    Vec3 pins = Vec3::Zero(), free = Vec3::Zero();
    Real n_pins = 0, n_free = 0;
    for (Eigen::Index i = 0; i < w.size(); ++i) {
        if (w[i] == 0) {
            pins += b.rest_local.col(i);
            n_pins += 1;
        } else {
            free += b.rest_local.col(i);
            n_free += 1;
        }
    }
    if (n_pins == 0 || n_free == 0) return Vec3::UnitY();
    const Vec3 local = pins / n_pins - free / n_free;
    if (!(local.norm() > Real(1e-6))) return Vec3::UnitY();
    const Vec3 up = anchor_frame(frames, b.anchor).linear() * local.normalized();
    return up.allFinite() ? up : Vec3::UnitY();
}

namespace {

// A run of consecutive particles (the fabric's order keeps neighbours together) and the box
// round them; `finite` false: a non-finite coordinate among them, no box.
struct ParticleBlock {
    Eigen::Index first = 0, end = 0;
    Vec3 low, high;
    bool finite = true;
};

std::vector<ParticleBlock> particle_blocks(const Matrix3X& x) {
    constexpr Eigen::Index size = 64;
    std::vector<ParticleBlock> blocks;
    blocks.reserve(static_cast<std::size_t>((x.cols() + size - 1) / size));
    for (Eigen::Index first = 0; first < x.cols(); first += size) {
        ParticleBlock b;
        b.first = first;
        b.end = std::min(first + size, x.cols());
        const auto part = x.middleCols(first, b.end - first);
        b.finite = part.allFinite();
        if (b.finite) {
            b.low = part.rowwise().minCoeff();
            b.high = part.rowwise().maxCoeff();
        }
        blocks.push_back(b);
    }
    return blocks;
}

}  // namespace

GarmentQuality measure_garment(const Garment& g, std::span<const EllipsoidFrame> frames, StrainHistogram* histogram,
                               Real ground_m) {
    GarmentQuality q;
    if (!g.fabric) return q;
    const Fabric& t = *g.fabric;
    const Matrix3X& x = g.state.x;
    const VectorX& w = g.state.inv_mass;
    q.nonfinite = static_cast<std::uint64_t>((!x.array().isFinite()).count() + (!g.state.v.array().isFinite()).count());

    std::vector<Real> strains;
    strains.reserve(t.warp1.size() + t.warp2.size() + t.weft.size());
    Real worst = -1;
    for (const SpringPhase* phase : {&t.warp1, &t.warp2, &t.weft})
        for (std::size_t s = 0; s < phase->size(); ++s) {
            const std::uint32_t a = phase->a[s], b = phase->b[s];
            const Real ratio = (x.col(b) - x.col(a)).norm() / phase->rest_m[s];
            if (w[a] == 0 && w[b] == 0) {
                q.pinned_strain_max = std::max(q.pinned_strain_max, std::isfinite(ratio) ? ratio - 1 : std::numeric_limits<Real>::infinity());
                continue;
            }
            if (std::isfinite(ratio)) q.compression_min = std::min(q.compression_min, ratio);
            const Real strain = std::isfinite(ratio) ? std::max(Real(0), ratio - 1) : std::numeric_limits<Real>::infinity();
            strains.push_back(strain);
            if (strain > worst) {
                worst = strain;
                q.worst_a = a;
                q.worst_b = b;
            }
        }
    q.springs = strains.size();
    if (histogram) histogram->add(strains);
    if (!strains.empty()) {
        // The p99 is the k-th of the strains in ascending order: the least of the largest
        // n - k, kept in a min-heap as the strains pass (no NaN: a total order).
        const std::size_t k = std::min(strains.size() - 1, static_cast<std::size_t>(std::ceil(0.99 * double(strains.size()))) - 1);
        const std::size_t top = strains.size() - k;
        std::vector<Real> largest(strains.begin(), strains.begin() + static_cast<std::ptrdiff_t>(top));
        std::make_heap(largest.begin(), largest.end(), std::greater<>());
        for (std::size_t s = top; s < strains.size(); ++s)
            if (strains[s] > largest.front()) {
                std::pop_heap(largest.begin(), largest.end(), std::greater<>());
                largest.back() = strains[s];
                std::push_heap(largest.begin(), largest.end(), std::greater<>());
            }
        q.strain_p99 = largest.front();
        q.strain_max = worst;
    }

    const Vec3 up = body_up(g, frames);
    Real highest_pin = -std::numeric_limits<Real>::infinity();
    for (Eigen::Index i = 0; i < x.cols(); ++i)
        if (w[i] == 0) highest_pin = std::max(highest_pin, up.dot(x.col(i)));
    for (Eigen::Index i = 0; i < x.cols(); ++i)
        if (w[i] != 0 && std::isfinite(highest_pin) && x.col(i).allFinite())
            q.rise_above_pins_m = std::max(q.rise_above_pins_m, up.dot(x.col(i)) - highest_pin);
    if (ground_m > -std::numeric_limits<Real>::infinity())
        for (Eigen::Index i = 0; i < x.cols(); ++i)
            if (w[i] != 0 && std::isfinite(x(1, i))) q.below_ground_m = std::max(q.below_ground_m, ground_m - x(1, i));
    // Depths: each ellipsoid against the particles in its bounding box only (blocks of
    // neighbouring particles whose box misses it skipped whole); past its give where it
    // gives (collision.hpp), the depth within the give kept apart.
    const std::vector<ParticleBlock> blocks = particle_blocks(x);
    for (std::size_t e = 0; e < frames.size(); ++e) {
        const EllipsoidFrame& f = frames[e];
        if (!f.active) continue;
        const Vec3 half = f.rotation.cwiseAbs() * f.radii_m;
        const Vec3 low = f.center - half, high = f.center + half;
        for (const ParticleBlock& block : blocks) {
            if (block.finite && ((block.high.array() < low.array()).any() || (block.low.array() > high.array()).any())) continue;
            for (Eigen::Index i = block.first; i < block.end; ++i) {
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
    }
    return q;
}

SpringPlace place_spring(const Garment& g, std::span<const EllipsoidFrame> frames, std::uint32_t a, std::uint32_t b) {
    SpringPlace place;
    if (!g.fabric) return place;
    const Fabric& t = *g.fabric;
    const std::uint32_t m = t.particles_per_line;
    place.rows = m;
    // Grid places of the two ends (Fabric::grid maps a place to its particle).
    std::size_t at_a = t.grid.size(), at_b = t.grid.size();
    for (std::size_t k = 0; k < t.grid.size(); ++k) {
        if (t.grid[k] == a) at_a = k;
        if (t.grid[k] == b) at_b = k;
    }
    if (at_a == t.grid.size() || at_b == t.grid.size() || m == 0) return place;
    place.line = static_cast<std::uint32_t>(at_a / m);
    place.row = static_cast<std::uint32_t>(at_a % m);
    place.weft = at_a / m != at_b / m;
    const Matrix3X& x = g.state.x;
    const Vec3 middle = Real(0.5) * (x.col(a) + x.col(b));
    if (!middle.allFinite()) return place;
    Real nearest = std::numeric_limits<Real>::infinity();
    for (std::size_t e = 0; e < frames.size(); ++e) {
        if (!frames[e].active) continue;
        const Real d = to_unit_sphere(frames[e], middle).norm();
        if (d < nearest) {
            nearest = d;
            place.collider = static_cast<std::int32_t>(e);
        }
    }
    if (place.collider < 0) return place;
    const EllipsoidFrame& f = frames[static_cast<std::size_t>(place.collider)];
    place.thickness_m = f.radii_m.minCoeff();
    place.unit_distance = nearest;
    const Vec3 ua = to_unit_sphere(f, x.col(a)).normalized(), ub = to_unit_sphere(f, x.col(b)).normalized();
    place.straddles = nearest < 1 && ua.dot(ub) < Real(0.5);
    return place;
}

GarmentQuality measure_garment(const Registry& registry, const Garment& garment, StrainHistogram* histogram) {
    std::vector<EllipsoidFrame> frames;
    update_frames(registry, garment.body, frames, 1);
    return measure_garment(garment, frames, histogram, ground_height(registry));
}

double hem_radius_m(const Fabric& f, const Matrix3X& x, bool grid_order) {
    const std::uint32_t m = f.particles_per_line;
    const auto at = [&](std::uint32_t line, std::uint32_t row) -> Vec3 {
        return x.col(grid_order ? line * m + row : f.grid[line * m + row]);
    };
    Vec3 centre = Vec3::Zero();
    for (std::uint32_t line = 0; line < f.warp_lines; ++line) centre += at(line, 0);
    centre /= static_cast<Real>(f.warp_lines);
    double sum = 0;
    for (std::uint32_t line = 0; line < f.warp_lines; ++line) {
        const Vec3 p = at(line, m - 1);
        sum += std::hypot(double(p.x() - centre.x()), double(p.z() - centre.z()));
    }
    return sum / f.warp_lines;
}

double kinetic_energy_J(const Matrix3X& v, const VectorX& inv_mass) {
    double e = 0;
    for (Eigen::Index i = 0; i < v.cols() && i < inv_mass.size(); ++i)
        if (inv_mass[i] > 0) e += 0.5 / inv_mass[i] * static_cast<double>(v.col(i).squaredNorm());
    return e;
}

}  // namespace drape
