// Constraints in compliance form; step order in constraints.hpp.
#include "drape/systems/cloth/constraints.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace drape {

std::vector<Real> spring_compliance(const SpringPhase& springs, const VectorX& area, Real modulus) {
    std::vector<Real> c(springs.size());
    for (std::size_t s = 0; s < springs.size(); ++s) {
        const Real rest = springs.rest_m[s];
        const Real k = modulus * (area[springs.a[s]] + area[springs.b[s]]) / (2 * rest * rest);
        c[s] = k > Real(1e-30) ? std::min(Real(1e30), 1 / k) : Real(1e30);
    }
    return c;
}

std::uint64_t provot_pass(const SpringPhase& sp, const VectorX& w, Real limit, Matrix3X& x) {
    std::uint64_t corrected = 0;
    const Real scale = 1 + limit;
    for (std::size_t s = 0; s < sp.size(); ++s) {
        const std::uint32_t a = sp.a[s], b = sp.b[s];
        const bool free_a = w[a] != 0, free_b = w[b] != 0;
        if (!free_a && !free_b) continue;
        const Vec3 d = x.col(b) - x.col(a);
        const Real len = d.norm(), bound = scale * sp.rest_m[s];
        if (!(len > bound)) continue;
        const Vec3 back = ((len - bound) / len) * d;  // what brings b back toward a to the bound
        const Real share_a = free_a && free_b ? Real(0.5) : (free_a ? Real(1) : Real(0));
        x.col(a) += share_a * back;
        x.col(b) -= (1 - share_a) * back;
        ++corrected;
    }
    return corrected;
}

std::vector<SpringStrip> spring_strips(const SpringPhase& sp) {
    std::vector<SpringStrip> strips;
    const std::uint32_t n = static_cast<std::uint32_t>(sp.size());
    std::uint32_t s = 0;
    while (s < n) {
        // The longest run from s of consecutive ends.
        std::uint32_t len = 1;
        while (s + len < n && sp.a[s + len] == sp.a[s] + len && sp.b[s + len] == sp.b[s] + len) ++len;
        const std::uint32_t a = sp.a[s], b = sp.b[s];
        const std::uint32_t gap = a > b ? a - b : b - a;
        if (gap >= len) {
            strips.push_back({a, b, s, len, 1});  // the two ends' ranges do not meet
        } else if (gap == 1) {
            // A chain: its even springs, then its odd ones.
            strips.push_back({a, b, s, (len + 1) / 2, 2});
            if (len > 1) strips.push_back({a + 1, b + 1, s + 1, len / 2, 2});
        } else {
            // Blocks of `gap` springs are independent; one after the other, in order (a warp
            // phase: row after row from the fitting zone down, as Gauss-Seidel hangs a line).
            for (std::uint32_t k = 0; k < len; k += gap) strips.push_back({a + k, b + k, s + k, std::min(gap, len - k), 1});
        }
        s += len;
    }
    return strips;
}

namespace {

// One strip (constraints.hpp step 3): XPBD, then Provot's limit, every spring in its own
// vector lane. Pointers are the strip's first entries; `Stride` its stride. The a and b
// entries of a strip are distinct particles (spring_strips), so nothing aliases.
template <int Stride>
void solve_strip(int count, Real* __restrict a0, Real* __restrict a1, Real* __restrict a2, Real* __restrict b0,
                 Real* __restrict b1, Real* __restrict b2, const Real* __restrict wa_, const Real* __restrict wb_,
                 const Real* __restrict rest, const Real* __restrict compliance, Real* __restrict lambda, Real inv_h2,
                 Real limit_scale) {
#pragma GCC ivdep
    for (int k = 0; k < count; ++k) {
        const int i = k * Stride;
        const Real d0 = b0[i] - a0[i], d1 = b1[i] - a1[i], d2 = b2[i] - a2[i];
        const Real length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
        const Real wa = wa_[i], wb = wb_[i], wsum = wa + wb;
        const Real r = rest[i];
        // XPBD: dlambda = (-C - alpha~ lambda) / (w_a + w_b + alpha~), C = length - rest.
        const Real alpha = compliance[i] * inv_h2;
        const Real lam = lambda[i];
        Real dl = (r - length - alpha * lam) / (wsum + alpha);
        lambda[i] = lam + dl;
        // Provot: whatever is left beyond the limit goes entirely.
        const Real over = length + dl * wsum - limit_scale * r;
        const Real excess = over > 0 ? over : Real(0);
        dl -= excess / (wsum + Real(1e-30));
        const Real scale = dl / (length + Real(1e-30));  // coincident ends: no direction, no move
        const Real m0 = scale * d0, m1 = scale * d1, m2 = scale * d2;
        a0[i] -= wa * m0;
        a1[i] -= wa * m1;
        a2[i] -= wa * m2;
        b0[i] += wb * m0;
        b1[i] += wb * m1;
        b2[i] += wb * m2;
    }
}

}  // namespace

BandStrips split_strips(const std::vector<SpringStrip>& strips, const std::vector<std::uint32_t>& band, std::size_t bands) {
    BandStrips out;
    out.parts.resize(bands);
    if (bands == 1) {
        out.parts[0] = strips;
        return out;
    }
    for (const SpringStrip& st : strips) {
        // Lane k's band, or bands (an edge spring) when its ends are in two.
        const auto lane_band = [&](std::uint32_t k) {
            const std::uint32_t a = band[st.a + k * st.stride], b = band[st.b + k * st.stride];
            return a == b ? a : static_cast<std::uint32_t>(bands);
        };
        std::uint32_t k = 0;
        while (k < st.count) {
            const std::uint32_t b = lane_band(k);
            std::uint32_t len = 1;
            while (k + len < st.count && lane_band(k + len) == b) ++len;
            for (std::uint32_t i = 0; i < (b == bands ? len : 1); ++i) {
                const std::uint32_t first = k + i;
                const SpringStrip piece{st.a + first * st.stride, st.b + first * st.stride, st.first + first * st.stride,
                                        b == bands ? 1 : len, st.stride};
                (b == bands ? out.edge : out.parts[b]).push_back(piece);
            }
            k += len;
        }
    }
    return out;
}

void solve_springs(SpringSet& set, std::size_t band, Matrix3XRows& x, const VectorX& w, Real h, Real limit) {
    Real* x0 = x.row(0).data();
    Real* x1 = x.row(1).data();
    Real* x2 = x.row(2).data();
    const Real inv_h2 = 1 / (h * h);
    const Real limit_scale = set.limited ? 1 + limit : std::numeric_limits<Real>::infinity();
    const Real* rest = set.springs->rest_m.data();
    const Real* compliance = set.compliance.data();
    Real* lambda = set.lambda.data();
    const Real* wp = w.data();
    for (const SpringStrip& st : set.strips.parts[band]) {
        const int count = static_cast<int>(st.count);
        const std::uint32_t a = st.a, b = st.b, f = st.first;
        if (st.stride == 1)
            solve_strip<1>(count, x0 + a, x1 + a, x2 + a, x0 + b, x1 + b, x2 + b, wp + a, wp + b, rest + f, compliance + f,
                           lambda + f, inv_h2, limit_scale);
        else
            solve_strip<2>(count, x0 + a, x1 + a, x2 + a, x0 + b, x1 + b, x2 + b, wp + a, wp + b, rest + f, compliance + f,
                           lambda + f, inv_h2, limit_scale);
    }
}

namespace {

// The edge springs of `set`, coordinate k of particle p at x[k] + p * stride.
void solve_edge_strips(SpringSet& set, std::array<Real*, 3> x, std::ptrdiff_t stride, const VectorX& w, Real h, Real limit) {
    const Real inv_h2 = 1 / (h * h);
    const Real limit_scale = set.limited ? 1 + limit : std::numeric_limits<Real>::infinity();
    for (const SpringStrip& st : set.strips.edge) {  // one spring each: a lane of one
        const std::ptrdiff_t a = st.a * stride, b = st.b * stride;
        solve_strip<1>(1, x[0] + a, x[1] + a, x[2] + a, x[0] + b, x[1] + b, x[2] + b, w.data() + st.a, w.data() + st.b,
                       set.springs->rest_m.data() + st.first, set.compliance.data() + st.first, set.lambda.data() + st.first,
                       inv_h2, limit_scale);
    }
}

}  // namespace

void solve_edge_springs(SpringSet& set, Matrix3X& x, const VectorX& w, Real h, Real limit) {
    solve_edge_strips(set, {x.data(), x.data() + 1, x.data() + 2}, 3, w, h, limit);
}

void solve_edge_springs(SpringSet& set, Matrix3XRows& x, const VectorX& w, Real h, Real limit) {
    solve_edge_strips(set, {x.row(0).data(), x.row(1).data(), x.row(2).data()}, 1, w, h, limit);
}

bool line_chains(SpringSet& set) {
    const SpringPhase& sp = *set.springs;
    const std::size_t n = sp.size();
    std::uint32_t particles = 0;
    for (std::size_t k = 0; k < n; ++k) particles = std::max({particles, sp.a[k] + 1, sp.b[k] + 1});
    std::vector<std::uint32_t> upper_end_of(particles, no_spring);  // per particle: the spring it is the upper end of
    for (std::size_t k = 0; k < n; ++k) upper_end_of[sp.a[k]] = static_cast<std::uint32_t>(k);
    set.prev.assign(n, no_spring);
    set.next.assign(n, no_spring);
    for (std::size_t k = 0; k < n; ++k) {
        set.next[k] = upper_end_of[sp.b[k]];
        if (set.next[k] != no_spring) set.prev[set.next[k]] = static_cast<std::uint32_t>(k);
    }
    const std::size_t bands = set.strips.parts.size();
    set.aligned_prev.assign(bands, {});
    set.aligned_next.assign(bands, {});
    std::vector<char> seen(n, 0);
    bool ordered = set.strips.edge.empty();
    for (std::size_t band = 0; band < bands && ordered; ++band) {
        const std::vector<SpringStrip>& strips = set.strips.parts[band];
        std::vector<std::uint8_t>& up = set.aligned_prev[band];
        std::vector<std::uint8_t>& down = set.aligned_next[band];
        up.assign(strips.size(), 0);
        down.assign(strips.size(), 0);
        for (std::size_t j = 0; j < strips.size() && ordered; ++j) {
            const SpringStrip& st = strips[j];
            bool up_ok = j > 0 && st.stride == 1 && strips[j - 1].stride == 1 && strips[j - 1].count >= st.count;
            for (std::uint32_t k = 0; k < st.count; ++k) {
                const std::uint32_t s = st.first + k * st.stride;
                ordered = ordered && (set.prev[s] == no_spring || seen[set.prev[s]]);
                seen[s] = 1;
                up_ok = up_ok && set.prev[s] == strips[j - 1].first + k;
            }
            up[j] = up_ok;
            if (up_ok) {
                // Strip j - 1's lanes beyond st.count have no spring below them in strip j.
                bool down_ok = true;
                for (std::uint32_t k = st.count; k < strips[j - 1].count; ++k)
                    down_ok = down_ok && set.next[strips[j - 1].first + k] == no_spring;
                down[j - 1] = down_ok;
            }
        }
    }
    if (!ordered) {
        set.prev.clear();
        set.next.clear();
        return false;
    }
    for (auto* v : {&set.dir0, &set.dir1, &set.dir2, &set.offdiag, &set.pivot, &set.rhs}) v->assign(n, 0);
    return true;
}

namespace {

// solve_lines' first sweep over one strip: each spring's direction, diagonal
// w_a + w_b + alpha~ and right-hand side -C - alpha~ lambda, and the largest right-hand
// side over its rest length (what is left of the spring's solution, as a strain).
template <int Stride>
void line_strip_terms(std::uint32_t count, const Real* __restrict a0, const Real* __restrict a1, const Real* __restrict a2,
                      const Real* __restrict b0, const Real* __restrict b1, const Real* __restrict b2,
                      const Real* __restrict wa, const Real* __restrict wb, const Real* __restrict rest,
                      const Real* __restrict compliance, const Real* __restrict lambda, Real inv_h2, Real* __restrict u0,
                      Real* __restrict u1, Real* __restrict u2, Real* __restrict pivot, Real* __restrict rhs,
                      Real& largest_residual) {
    Real largest = largest_residual;
#pragma GCC ivdep
    for (int k = 0; k < int(count); ++k) {
        const int i = k * Stride;
        const Real d0 = b0[i] - a0[i], d1 = b1[i] - a1[i], d2 = b2[i] - a2[i];
        const Real length = std::sqrt(d0 * d0 + d1 * d1 + d2 * d2);
        const Real inv = 1 / std::max(length, Real(1e-12));  // coincident ends: no direction, no move
        u0[i] = d0 * inv;
        u1[i] = d1 * inv;
        u2[i] = d2 * inv;
        const Real alpha = compliance[i] * inv_h2;
        pivot[i] = std::max(wa[i] + wb[i] + alpha, Real(1e-30));
        rhs[i] = rest[i] - length - alpha * lambda[i];
        largest = std::max(largest, std::abs(rhs[i]) / rest[i]);
    }
    largest_residual = largest;
}

// solve_lines' elimination of a strip's coupling with the strip above it, lane by lane:
// c = -w_shared (u_above . u), pivot -= c^2 / pivot_above, rhs -= c rhs_above / pivot_above.
void eliminate_strip(int count, const Real* __restrict w_shared, const Real* __restrict v0, const Real* __restrict v1,
                     const Real* __restrict v2, const Real* __restrict pivot_above, const Real* __restrict rhs_above,
                     const Real* __restrict u0, const Real* __restrict u1, const Real* __restrict u2, Real* __restrict off,
                     Real* __restrict pivot, Real* __restrict rhs) {
    for (int k = 0; k < count; ++k) {
        const Real c = -w_shared[k] * (v0[k] * u0[k] + v1[k] * u1[k] + v2[k] * u2[k]);
        const Real q = c / pivot_above[k];
        off[k] = c;
        pivot[k] = std::max(pivot[k] - c * q, Real(1e-30));
        rhs[k] -= q * rhs_above[k];
    }
}

// solve_lines' last sweep over one strip: each spring's multiplier and its ends' moves.
template <int Stride>
void line_strip_moves(std::uint32_t count, Real* __restrict a0, Real* __restrict a1, Real* __restrict a2,
                      Real* __restrict b0, Real* __restrict b1, Real* __restrict b2, const Real* __restrict wa,
                      const Real* __restrict wb, const Real* __restrict u0, const Real* __restrict u1,
                      const Real* __restrict u2, const Real* __restrict dl_, Real* __restrict lambda) {
#pragma GCC ivdep
    for (int k = 0; k < int(count); ++k) {
        const int i = k * Stride;
        const Real dl = dl_[i];
        lambda[i] += dl;
        const Real m0 = dl * u0[i], m1 = dl * u1[i], m2 = dl * u2[i];
        a0[i] -= wa[i] * m0;
        a1[i] -= wa[i] * m1;
        a2[i] -= wa[i] * m2;
        b0[i] += wb[i] * m0;
        b1[i] += wb[i] * m1;
        b2[i] += wb[i] * m2;
    }
}

}  // namespace

int solve_lines(SpringSet& set, std::size_t band, Matrix3XRows& x, const VectorX& w_, Real h, int max_iterations,
                Real tolerance) {
    const SpringPhase& sp = *set.springs;
    Real* x0 = x.row(0).data();
    Real* x1 = x.row(1).data();
    Real* x2 = x.row(2).data();
    const Real* w = w_.data();
    const Real inv_h2 = 1 / (h * h);
    const Real* rest = sp.rest_m.data();
    const Real* compliance = set.compliance.data();
    Real* lambda = set.lambda.data();
    Real* __restrict u0 = set.dir0.data();
    Real* __restrict u1 = set.dir1.data();
    Real* __restrict u2 = set.dir2.data();
    Real* __restrict off = set.offdiag.data();  // per spring: its coupling with the spring above it
    Real* __restrict pivot = set.pivot.data();
    Real* __restrict rhs = set.rhs.data();      // the right-hand side, eliminated, then the multiplier's change
    const std::uint32_t* prev = set.prev.data();
    const std::uint32_t* next = set.next.data();
    const std::vector<SpringStrip>& strips = set.strips.parts[band];
    const std::vector<std::uint8_t>& aligned_prev = set.aligned_prev[band];
    const std::vector<std::uint8_t>& aligned_next = set.aligned_next[band];
    // From the pins down, strip by strip (a strip is a row of lines): each spring's terms,
    // then the elimination of its coupling with the spring above it, -w_shared (u_above . u).
    // Returns the largest right-hand side over its spring's rest length.
    auto eliminate = [&]() {
        Real largest_residual = 0;
        for (std::size_t j = 0; j < strips.size(); ++j) {
            const SpringStrip& st = strips[j];
            const std::uint32_t count = st.count, stride = st.stride, f = st.first, a = st.a, b = st.b;
            if (stride == 1)
                line_strip_terms<1>(count, x0 + a, x1 + a, x2 + a, x0 + b, x1 + b, x2 + b, w + a, w + b, rest + f,
                                    compliance + f, lambda + f, inv_h2, u0 + f, u1 + f, u2 + f, pivot + f, rhs + f,
                                    largest_residual);
            else
                line_strip_terms<2>(count, x0 + a, x1 + a, x2 + a, x0 + b, x1 + b, x2 + b, w + a, w + b, rest + f,
                                    compliance + f, lambda + f, inv_h2, u0 + f, u1 + f, u2 + f, pivot + f, rhs + f,
                                    largest_residual);
            if (j > 0 && aligned_prev[j]) {
                const std::uint32_t above = strips[j - 1].first;
                eliminate_strip(int(count), w + a, u0 + above, u1 + above, u2 + above, pivot + above, rhs + above, u0 + f,
                                u1 + f, u2 + f, off + f, pivot + f, rhs + f);
            } else {
                for (std::uint32_t k = 0; k < count; ++k) {
                    const std::uint32_t s = f + k * stride, p = prev[s];
                    off[s] = 0;
                    if (p == no_spring) continue;
                    const Real c = -w[a + k * stride] * (u0[p] * u0[s] + u1[p] * u1[s] + u2[p] * u2[s]);
                    const Real q = c / pivot[p];
                    off[s] = c;
                    pivot[s] = std::max(pivot[s] - c * q, Real(1e-30));
                    rhs[s] -= q * rhs[p];
                }
            }
        }
        return largest_residual;
    };
    // From the hem up: each multiplier's change, then its spring's move (the directions and
    // the springs above no longer need the positions).
    auto substitute = [&]() {
        for (std::size_t j = strips.size(); j-- > 0;) {
            const SpringStrip& st = strips[j];
            const std::uint32_t count = st.count, stride = st.stride, f = st.first, a = st.a, b = st.b;
            if (aligned_next[j]) {
                const int below = int(strips[j + 1].count);
                Real* __restrict y = rhs + f;
                const Real* __restrict y_below = rhs + strips[j + 1].first;
                const Real* __restrict c_below = off + strips[j + 1].first;
                const Real* __restrict p = pivot + f;
                for (int k = 0; k < below; ++k) y[k] = (y[k] - c_below[k] * y_below[k]) / p[k];
                for (int k = below; k < int(count); ++k) y[k] /= p[k];
            } else {
                for (std::uint32_t k = 0; k < count; ++k) {
                    const std::uint32_t s = f + k * stride, t = next[s];
                    rhs[s] = (rhs[s] - (t == no_spring ? Real(0) : off[t] * rhs[t])) / pivot[s];
                }
            }
            if (stride == 1)
                line_strip_moves<1>(count, x0 + a, x1 + a, x2 + a, x0 + b, x1 + b, x2 + b, w + a, w + b, u0 + f, u1 + f,
                                    u2 + f, rhs + f, lambda + f);
            else
                line_strip_moves<2>(count, x0 + a, x1 + a, x2 + a, x0 + b, x1 + b, x2 + b, w + a, w + b, u0 + f, u1 + f,
                                    u2 + f, rhs + f, lambda + f);
        }
    };
    // Newton's iterations on the lines' constraints: the first always taken (one solve a
    // round), then more while a spring is farther than `tolerance` (a strain) from its
    // solution, up to `max_iterations`.
    int iteration = 0;
    for (; iteration < std::max(max_iterations, 1); ++iteration) {
        if (eliminate() <= tolerance && iteration > 0) break;
        substitute();
    }
    return iteration;
}

VectorX warp_rest_above(const Fabric& f) {
    VectorX above = VectorX::Zero(static_cast<Eigen::Index>(f.particle_count()));
    for (const SpringPhase* phase : {&f.warp1, &f.warp2})
        for (std::size_t s = 0; s < phase->size(); ++s) above[phase->b[s]] = phase->rest_m[s];
    return above;
}

Tethers build_tethers(const Fabric& f, const VectorX& w, const VectorX& above) {
    Tethers t;
    const std::uint32_t m = f.particles_per_line;
    for (std::uint32_t line = 0; line < f.warp_lines; ++line) {
        std::uint32_t anchor = std::numeric_limits<std::uint32_t>::max();
        Real along = 0;
        for (std::uint32_t row = 0; row < m; ++row) {
            const std::uint32_t p = f.grid[line * m + row];
            if (w[p] == 0) {
                anchor = p;
                along = 0;
                continue;
            }
            along += above[p];
            if (anchor == std::numeric_limits<std::uint32_t>::max()) continue;
            t.particle.push_back(p);
            t.anchor.push_back(anchor);
            t.length_m.push_back(along);
        }
    }
    return t;
}

std::vector<Tethers> split_tethers(const Tethers& t, const std::vector<std::uint32_t>& band, std::size_t bands) {
    std::vector<Tethers> parts(bands);
    for (std::size_t k = 0; k < t.particle.size(); ++k) {
        Tethers& part = parts[band[t.particle[k]]];
        part.particle.push_back(t.particle[k]);
        part.anchor.push_back(t.anchor[k]);
        part.length_m.push_back(t.length_m[k]);
    }
    return parts;
}

void solve_tethers(const Tethers& t, Matrix3XRows& x) {
    Real* x0 = x.row(0).data();
    Real* x1 = x.row(1).data();
    Real* x2 = x.row(2).data();
    for (std::size_t k = 0; k < t.particle.size(); ++k) {
        const std::uint32_t p = t.particle[k], q = t.anchor[k];
        const Real d0 = x0[p] - x0[q], d1 = x1[p] - x1[q], d2 = x2[p] - x2[q];
        const Real max_length = t.length_m[k];
        const Real length_sq = d0 * d0 + d1 * d1 + d2 * d2;
        if (length_sq <= max_length * max_length) continue;
        const Real scale = max_length / std::sqrt(length_sq);
        x0[p] = x0[q] + d0 * scale;
        x1[p] = x1[q] + d1 * scale;
        x2[p] = x2[q] + d2 * scale;
    }
}

namespace {

// Each tethered particle outside its sphere, centred at `centre(p)`, of share x its tether's
// length goes onto it.
template <class Centre>
void keep_within_spheres(const Tethers& t, Real share, Matrix3XRows& x, Centre&& centre) {
    Real* x0 = x.row(0).data();
    Real* x1 = x.row(1).data();
    Real* x2 = x.row(2).data();
    for (std::size_t k = 0; k < t.particle.size(); ++k) {
        const std::uint32_t p = t.particle[k];
        const Vec3 target = centre(p);
        const Real d0 = x0[p] - target[0], d1 = x1[p] - target[1], d2 = x2[p] - target[2];
        const Real radius = share * t.length_m[k];
        const Real distance_sq = d0 * d0 + d1 * d1 + d2 * d2;
        if (distance_sq <= radius * radius) continue;
        const Real scale = radius / std::sqrt(distance_sq);
        x0[p] = target[0] + d0 * scale;
        x1[p] = target[1] + d1 * scale;
        x2[p] = target[2] + d2 * scale;
    }
}

}  // namespace

void solve_max_distance(const Tethers& t, const Matrix3X& rest_local, const Affine3& anchor, Real share, Matrix3XRows& x) {
    if (!(share > 0) || rest_local.cols() == 0) return;  // a rest shape is one column per particle
    const Mat3 r = anchor.linear();
    const Vec3 c = anchor.translation();
    keep_within_spheres(t, share, x, [&](std::uint32_t p) { return Vec3(r * rest_local.col(p) + c); });
}

void solve_max_distance(const Tethers& t, const Matrix3X& previous, const Matrix3X& target, Real alpha, const Matrix3X& rest_local,
                        const Affine3& anchor, Real share, Matrix3XRows& x) {
    if (!(share > 0) || target.cols() != x.cols() || previous.cols() != x.cols() || rest_local.cols() != x.cols()) return;
    const Mat3 r = anchor.linear();
    const Vec3 c = anchor.translation();
    keep_within_spheres(t, share, x, [&](std::uint32_t p) {
        Vec3 centre = (1 - alpha) * previous.col(p) + alpha * target.col(p);
        centre[1] = std::min(centre[1], (r * rest_local.col(p) + c)[1]);  // never above the anchor's
        return centre;
    });
}

std::uint64_t limit_warp_lines(const Fabric& f, const VectorX& rest_above, const VectorX& w, Real stretch, Matrix3X& x,
                               Matrix3X& moves, std::uint32_t first_line, std::uint32_t end_line) {
    std::uint64_t moved = 0;
    const std::uint32_t m = f.particles_per_line;
    for (std::uint32_t line = first_line; line < end_line; ++line)
        for (std::uint32_t row = 0; row < m; ++row) moves.col(f.grid[line * m + row]).setZero();
    const Real scale = 1 + stretch;
    // Row after row from the fitting zone down, every line of the row in turn: the particle
    // above has its final place when its neighbour below is limited.
    for (std::uint32_t row = 1; row < m; ++row)
        for (std::uint32_t line = first_line; line < end_line; ++line) {
            const std::uint32_t p = f.grid[line * m + row], q = f.grid[line * m + row - 1];
            if (w[p] == 0) continue;
            const Vec3 d = x.col(p) - x.col(q);
            const Real length_sq = d.squaredNorm(), longest = scale * rest_above[p];
            if (length_sq <= longest * longest) continue;
            const Vec3 move = d * (longest / std::sqrt(length_sq) - 1);
            x.col(p) += move;
            moves.col(p) = move;
            ++moved;
        }
    return moved;
}

}  // namespace drape

namespace drape {

VectorX weft_rest_right(const Fabric& f) {
    VectorX right = VectorX::Zero(static_cast<Eigen::Index>(f.particle_count()));
    for (std::size_t s = 0; s < f.weft.size(); ++s) right[f.weft.a[s]] = f.weft.rest_m[s];
    return right;
}

namespace {

std::uint64_t limit_weft_row(const Fabric& f, const VectorX& rest_right, const VectorX& w, Real scale, Matrix3X& x,
                             Matrix3X& moves, std::uint32_t row, WeftLimitScratch& scratch) {
    const std::uint32_t m = f.particles_per_line, n = f.warp_lines;
    const std::uint32_t springs = f.closed ? n : n - 1;
    auto& [p, dir, excess, diag, upper, dl, sweep, dirty] = scratch;
    std::uint64_t corrected = 0;
    for (std::uint32_t line = 0; line < n; ++line) {
        p[line] = f.grid[line * m + row];
        moves.col(p[line]).setZero();
    }
    // Most rows have no spring over its bound (a dress's hem rows apart): the first pass's
    // test alone, without branches, with a little margin so that it never passes a row the
    // pass would find over; such a row is left as the pass would leave it.
    bool any = false;
    for (std::uint32_t i = 0; i < springs; ++i) {
        const std::uint32_t a = p[i], b = p[i + 1 < n ? i + 1 : 0];
        const Real bound = scale * rest_right[a];
        any |= (x.col(b) - x.col(a)).squaredNorm() > bound * bound * Real(0.999);
    }
    if (!any) return 0;
    std::fill(dirty.begin(), dirty.end(), char(1));
    for (int pass = 0; pass < weft_limit_passes; ++pass) {
        bool over = false;
        for (std::uint32_t i = 0; i < springs; ++i) {
            // After the first pass only the springs of and next to a corrected run can
            // have changed: the others stay within their bound.
            if (!dirty[i]) {
                excess[i] = -1;
                continue;
            }
            dirty[i] = 0;
            const std::uint32_t a = p[i], b = p[i + 1 < n ? i + 1 : 0];
            const Real bound = scale * rest_right[a];
            const Real length_sq = (x.col(b) - x.col(a)).squaredNorm();
            excess[i] = -1;  // within its bound, or between two pins (the skin decides)
            if (length_sq <= bound * bound || w[a] + w[b] == 0) continue;
            excess[i] = std::sqrt(length_sq) - bound;
            over = over || excess[i] > weft_limit_tolerance * rest_right[a];
        }
        if (!over) break;
        // Each run of over-long springs is one chain: its linearised constraints
        // K dl = -excess, K_jj = w_a + w_b, K_j,j+1 = -w_shared (u_j . u_j+1) with u the
        // springs' directions, a tridiagonal system solved directly (Thomas). A closed
        // row's runs start after a spring that is not over (all over: at line 0).
        std::uint32_t start = 0;
        if (f.closed) {
            while (start < springs && excess[start] > 0) ++start;
            if (start == springs) start = 0;
        }
        for (std::uint32_t k = 0; k < springs;) {
            if (!(excess[(start + k) % springs] > 0)) {
                ++k;
                continue;
            }
            std::uint32_t len = 0;
            while (k + len < springs && excess[(start + k + len) % springs] > 0) ++len;
            const auto spring = [&](std::uint32_t j) { return (start + k + j) % springs; };
            for (std::uint32_t j = 0; j < len; ++j) {
                const std::uint32_t i = spring(j), a = p[i], b = p[(i + 1) % n];
                dir[i] = (x.col(b) - x.col(a)).normalized();
            }
            for (std::uint32_t j = 0; j < len; ++j) {
                const std::uint32_t i = spring(j), a = p[i], b = p[(i + 1) % n];
                diag[j] = w[a] + w[b];
                upper[j] = j + 1 < len ? -w[b] * dir[i].dot(dir[spring(j + 1)]) : Real(0);
                // Forward sweep.
                const Real lower = j > 0 ? upper[j - 1] : Real(0);
                const Real denom = diag[j] - (j > 0 ? lower * sweep[j - 1] : Real(0));
                sweep[j] = upper[j] / denom;
                dl[j] = (-excess[i] - (j > 0 ? lower * dl[j - 1] : Real(0))) / denom;
            }
            for (std::uint32_t j = len - 1; j-- > 0;) dl[j] -= sweep[j] * dl[j + 1];
            for (std::uint32_t j = 0; j < len; ++j) {
                const std::uint32_t i = spring(j), a = p[i], b = p[(i + 1) % n];
                const Vec3 step = dir[i] * dl[j];
                x.col(a) -= w[a] * step;
                moves.col(a) -= w[a] * step;
                x.col(b) += w[b] * step;
                moves.col(b) += w[b] * step;
            }
            for (std::uint32_t j = 0; j < len + 2; ++j) dirty[(start + k + j + springs - 1) % springs] = 1;
            corrected += len;
            k += len;
        }
    }
    return corrected;
}

// The scratch sized for the fabric's rows: `given`, or a local one.
WeftLimitScratch& sized(const Fabric& f, WeftLimitScratch* given, WeftLimitScratch& local) {
    WeftLimitScratch& s = given != nullptr ? *given : local;
    const std::uint32_t lines = f.warp_lines, springs = f.closed ? f.warp_lines : f.warp_lines - 1;
    s.p.resize(lines);
    for (auto* v : {&s.excess, &s.diag, &s.upper, &s.dl, &s.sweep}) v->resize(springs);
    s.dir.resize(springs);
    s.dirty.resize(springs);
    return s;
}

}  // namespace

std::uint64_t limit_weft_rows(const Fabric& f, const VectorX& rest_right, const VectorX& w, Real stretch, Matrix3X& x,
                              Matrix3X& moves, std::uint32_t first_row, std::uint32_t end_row, WeftLimitScratch* given) {
    WeftLimitScratch local;
    WeftLimitScratch& scratch = sized(f, given, local);
    std::uint64_t corrected = 0;
    for (std::uint32_t row = first_row; row < end_row; ++row)
        corrected += limit_weft_row(f, rest_right, w, 1 + stretch, x, moves, row, scratch);
    return corrected;
}

std::uint64_t limit_weft_rows(const Fabric& f, const VectorX& rest_right, const VectorX& w, Real stretch, Matrix3X& x,
                              Matrix3X& moves, std::span<const std::uint32_t> rows, WeftLimitScratch* given) {
    WeftLimitScratch local;
    WeftLimitScratch& scratch = sized(f, given, local);
    std::uint64_t corrected = 0;
    for (const std::uint32_t row : rows) corrected += limit_weft_row(f, rest_right, w, 1 + stretch, x, moves, row, scratch);
    return corrected;
}

}  // namespace drape
