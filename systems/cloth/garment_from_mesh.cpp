#include "drape/systems/cloth/garment_from_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <sstream>

#include "drape/components/garment_surface.hpp"
#include "drape/components/body_landmarks.hpp"
#include "drape/components/character.hpp"
#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/skeleton.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/engine/assets/skinning.hpp"
#include "drape/systems/character/skin_surface.hpp"
#include "drape/systems/character/trunk_skin.hpp"
#include "drape/systems/cloth/body.hpp"
#include "drape/systems/cloth/garment_surface.hpp"
#include "drape/components/transform.hpp"

namespace drape {
namespace {

// The default distance between warp lines and between weft rows of a resampled grid: the
// built-in skirt's line spacing (TubeParams::line_spacing_m).
constexpr Real default_spacing_m = Real(0.029);

std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

// Sorted distinct values of `values`, those within `tolerance` of the previous one merged.
std::vector<Real> distinct(std::vector<Real> values, Real tolerance) {
    std::sort(values.begin(), values.end());
    std::vector<Real> out;
    for (Real v : values)
        if (out.empty() || v - out.back() > tolerance) out.push_back(v);
    return out;
}

// One panel of the pattern: a connected piece of the mesh, its triangles, its UV box and
// its scale on the surface (metres per unit of u and of v).
struct Panel {
    std::vector<std::size_t> triangles;  // first indices into GarmentMeshAsset::indices
    Real u0 = 0, u1 = 0, v0 = 0, v1 = 0;
    double per_u = 0, per_v = 0;
};

// The mesh's panels (connected pieces through shared vertices), in the order of their
// first triangles.
std::vector<Panel> find_panels(const GarmentMeshAsset& mesh) {
    std::vector<std::uint32_t> parent(mesh.vertex_count());
    std::iota(parent.begin(), parent.end(), 0u);
    const auto root = [&](std::uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        parent[root(mesh.indices[t + 1])] = root(mesh.indices[t]);
        parent[root(mesh.indices[t + 2])] = root(mesh.indices[t]);
    }
    std::vector<Panel> panels;
    std::vector<std::int64_t> panel_of(mesh.vertex_count(), -1);
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        std::int64_t& k = panel_of[root(mesh.indices[t])];
        if (k < 0) k = static_cast<std::int64_t>(panels.size()), panels.emplace_back();
        panels[static_cast<std::size_t>(k)].triangles.push_back(t);
    }
    for (Panel& panel : panels) {
        panel.u0 = panel.v0 = std::numeric_limits<Real>::infinity();
        panel.u1 = panel.v1 = -std::numeric_limits<Real>::infinity();
        double weight = 0;
        for (const std::size_t t : panel.triangles) {
            const auto i = [&](std::size_t k) { return mesh.indices[t + k]; };
            for (std::size_t k = 0; k < 3; ++k) {
                panel.u0 = std::min(panel.u0, mesh.uvs(0, i(k))), panel.u1 = std::max(panel.u1, mesh.uvs(0, i(k)));
                panel.v0 = std::min(panel.v0, mesh.uvs(1, i(k))), panel.v1 = std::max(panel.v1, mesh.uvs(1, i(k)));
            }
            Eigen::Matrix2d d;
            d.col(0) = (mesh.uvs.col(i(1)) - mesh.uvs.col(i(0))).cast<double>();
            d.col(1) = (mesh.uvs.col(i(2)) - mesh.uvs.col(i(0))).cast<double>();
            const double det = d.determinant();
            if (std::abs(det) < 1e-14) continue;
            Eigen::Matrix<double, 3, 2> e;
            e.col(0) = (mesh.positions.col(i(1)) - mesh.positions.col(i(0))).cast<double>();
            e.col(1) = (mesh.positions.col(i(2)) - mesh.positions.col(i(0))).cast<double>();
            const Eigen::Matrix<double, 3, 2> j = e * d.inverse();
            panel.per_u += j.col(0).norm() * std::abs(det);
            panel.per_v += j.col(1).norm() * std::abs(det);
            weight += std::abs(det);
        }
        if (weight > 0) panel.per_u /= weight, panel.per_v /= weight;
    }
    return panels;
}

// Where a UV point lies on the mesh: its triangle and barycentric weights.
struct SurfacePoint {
    std::size_t triangle = 0;  // first index into indices
    Real w0 = 0, w1 = 0, w2 = 0;
};

// Finds UV points' triangles in one panel through a bucket grid over its box.
class UvLocator {
public:
    UvLocator(const GarmentMeshAsset& mesh, const Panel& panel) : m_mesh(mesh), m_u0(panel.u0), m_v0(panel.v0) {
        m_cells = std::clamp<int>(static_cast<int>(std::sqrt(Real(panel.triangles.size()))), 1, 256);
        m_du = std::max(panel.u1 - panel.u0, Real(1e-12)) / Real(m_cells);
        m_dv = std::max(panel.v1 - panel.v0, Real(1e-12)) / Real(m_cells);
        m_buckets.resize(static_cast<std::size_t>(m_cells * m_cells));
        for (const std::size_t t : panel.triangles) {
            Real lo_u = std::numeric_limits<Real>::infinity(), hi_u = -lo_u, lo_v = lo_u, hi_v = -lo_u;
            for (std::size_t k = 0; k < 3; ++k) {
                const auto uv = mesh.uvs.col(mesh.indices[t + k]);
                lo_u = std::min(lo_u, uv.x()), hi_u = std::max(hi_u, uv.x());
                lo_v = std::min(lo_v, uv.y()), hi_v = std::max(hi_v, uv.y());
            }
            for (int i = cell_u(lo_u); i <= cell_u(hi_u); ++i)
                for (int j = cell_v(lo_v); j <= cell_v(hi_v); ++j) m_buckets[static_cast<std::size_t>(j * m_cells + i)].push_back(t);
        }
    }

    // The triangle holding (u, v), or the one it lies least outside of when that is within
    // `slack` in barycentric terms (a point on the panel's edge); none otherwise.
    [[nodiscard]] std::optional<SurfacePoint> locate(Real u, Real v, Real slack = Real(1e-4)) const {
        std::optional<SurfacePoint> best;
        double best_min = -std::numeric_limits<double>::infinity();
        for (const std::size_t t : m_buckets[static_cast<std::size_t>(cell_v(v) * m_cells + cell_u(u))]) {
            const Eigen::Vector2d a = m_mesh.uvs.col(m_mesh.indices[t]).cast<double>();
            const Eigen::Vector2d b = m_mesh.uvs.col(m_mesh.indices[t + 1]).cast<double>();
            const Eigen::Vector2d c = m_mesh.uvs.col(m_mesh.indices[t + 2]).cast<double>();
            const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
            if (std::abs(det) < 1e-18) continue;
            const Eigen::Vector2d q = Eigen::Vector2d(u, v) - a;
            const double w1 = (q.x() * (c - a).y() - q.y() * (c - a).x()) / det;
            const double w2 = ((b - a).x() * q.y() - (b - a).y() * q.x()) / det;
            const double w0 = 1 - w1 - w2;
            const double lowest = std::min({w0, w1, w2});
            if (lowest > best_min) {
                best_min = lowest;
                best = SurfacePoint{t, static_cast<Real>(w0), static_cast<Real>(w1), static_cast<Real>(w2)};
            }
        }
        if (!best || best_min < -slack) return std::nullopt;
        return best;
    }

    [[nodiscard]] Vec3 position(const SurfacePoint& s) const {
        const auto& x = m_mesh.positions;
        const auto& i = m_mesh.indices;
        return s.w0 * x.col(i[s.triangle]) + s.w1 * x.col(i[s.triangle + 1]) + s.w2 * x.col(i[s.triangle + 2]);
    }
    [[nodiscard]] Real pin(const SurfacePoint& s) const {
        const auto& i = m_mesh.indices;
        return s.w0 * m_mesh.pin[i[s.triangle]] + s.w1 * m_mesh.pin[i[s.triangle + 1]] + s.w2 * m_mesh.pin[i[s.triangle + 2]];
    }

private:
    [[nodiscard]] int cell_u(Real u) const { return std::clamp(static_cast<int>((u - m_u0) / m_du), 0, m_cells - 1); }
    [[nodiscard]] int cell_v(Real v) const { return std::clamp(static_cast<int>((v - m_v0) / m_dv), 0, m_cells - 1); }

    const GarmentMeshAsset& m_mesh;
    Real m_u0, m_v0, m_du = 1, m_dv = 1;
    int m_cells = 1;
    std::vector<std::vector<std::size_t>> m_buckets;
};

// Where the panel crosses the level v: the least and the greatest u of its triangles'
// edges there (a panel is one piece across at every level).
std::pair<Real, Real> row_span(const GarmentMeshAsset& mesh, const Panel& panel, Real v) {
    Real lo = std::numeric_limits<Real>::infinity(), hi = -lo;
    for (const std::size_t t : panel.triangles)
        for (std::size_t k = 0; k < 3; ++k) {
            const auto a = mesh.uvs.col(mesh.indices[t + k]), b = mesh.uvs.col(mesh.indices[t + (k + 1) % 3]);
            if ((a.y() - v) * (b.y() - v) > 0) continue;
            Real u = a.x();
            if (a.y() != b.y()) u = a.x() + (b.x() - a.x()) * (v - a.y()) / (b.y() - a.y());
            else lo = std::min(lo, b.x()), hi = std::max(hi, b.x());
            lo = std::min(lo, u), hi = std::max(hi, u);
        }
    return {lo, hi};
}

// One panel's grid: `lines` lines (its two side edges included) of `rows` rows, in grid
// order (line * rows + row), with the pin paint read at each point.
struct PanelGrid {
    int lines = 0;
    Matrix3X x;
    VectorX pin;
    int outside = 0;  // points that fell outside the panel
};

PanelGrid grid_panel(const GarmentMeshAsset& mesh, const Panel& panel, int segments, int rows, bool painted) {
    const UvLocator locator(mesh, panel);
    PanelGrid g;
    g.lines = segments + 1;
    g.x.resize(3, g.lines * rows);
    g.pin = VectorX::Zero(g.lines * rows);
    for (int row = 0; row < rows; ++row) {
        // Rows a hair inside the panel's ends, whose level may touch it at one point only.
        const Real t = std::clamp(Real(row) / Real(rows - 1), Real(1e-5), Real(1) - Real(1e-5));
        const Real v = panel.v0 + (panel.v1 - panel.v0) * t;
        const auto [lo, hi] = row_span(mesh, panel, v);
        for (int line = 0; line < g.lines; ++line) {
            const Real u = lo + (hi - lo) * Real(line) / Real(segments);
            const auto at = locator.locate(u, v);
            if (!at) {
                ++g.outside;
                g.x.col(line * rows + row).setZero();
                continue;
            }
            g.x.col(line * rows + row) = locator.position(*at);
            if (painted) g.pin[line * rows + row] = locator.pin(*at);
        }
    }
    return g;
}

// The mean distance between two lines of points (rows each).
Real line_gap(const Matrix3X& a, int line_a, const Matrix3X& b, int line_b, int rows) {
    return (a.middleCols(line_a * rows, rows) - b.middleCols(line_b * rows, rows)).colwise().norm().mean();
}

}  // namespace

Result<MeshGrid> grid_from_mesh(const GarmentMeshAsset& mesh, const MeshGarmentParams& params, std::string_view name) {
    const std::string p(name);
    const std::string what = mesh.name.empty() ? "the mesh" : "mesh '" + mesh.name + "'";
    if (!(params.spacing_m >= 0 && params.spacing_m <= 1)) return fail(p + ".spacing_m: must be in [0, 1] m, got " + number(params.spacing_m));
    if (params.weft_stride < 1 || params.weft_stride > 16) return fail(p + ".weft_stride: must be in [1, 16], got " + std::to_string(params.weft_stride));
    if (params.fitting_rows < 1 || params.fitting_rows > 16) return fail(p + ".fitting_rows: must be in [1, 16], got " + std::to_string(params.fitting_rows));
    if (mesh.indices.empty() || mesh.indices.size() % 3 != 0) return fail(p + ": " + what + " has no triangles");
    if (mesh.uvs.cols() != mesh.positions.cols())
        return fail(p + ": " + what + " has no UV coordinates: the simplified model takes its warp and weft from the pattern "
                                      "(derive_pattern gives it one from its shape)");
    const bool painted = params.pins == PinSource::painted || (params.pins == PinSource::file && mesh.pin.size() == mesh.positions.cols());
    if (painted && mesh.pin.size() != mesh.positions.cols())
        return fail(p + ".pins: " + what + " paints no pins (no COLOR_0): paint the held vertices red or use \"auto\"");

    std::vector<Panel> panels = find_panels(mesh);
    for (std::size_t k = 0; k < panels.size(); ++k)
        if (!(panels[k].u1 - panels[k].u0 > Real(1e-6) && panels[k].v1 - panels[k].v0 > Real(1e-6) && panels[k].per_u > 0))
            return fail(p + ": " + what + "'s panel " + std::to_string(k) + " spans no area in UV");
    const int stride = params.weft_stride;
    const Real spacing = params.spacing_m > 0 ? params.spacing_m : default_spacing_m;

    // The mesh's own lattice (one panel whose vertices are a u x v lattice, the files
    // garment_as_mesh writes): each grid point a vertex, taken as it is.
    std::vector<std::uint8_t> used(mesh.vertex_count(), 0);
    for (std::uint32_t v : mesh.indices) used[v] = 1;
    Matrix3X x;
    VectorX pin;
    int n = 0, m = 0;
    bool closed = false;
    std::string how;
    if (params.spacing_m == 0 && panels.size() == 1) {
        const Panel& panel = panels.front();
        std::vector<Real> us, vs;
        for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
            if (used[v]) us.push_back(mesh.uvs(0, v)), vs.push_back(mesh.uvs(1, v));
        const std::vector<Real> lu = distinct(us, Real(1e-5) * (panel.u1 - panel.u0)), lv = distinct(vs, Real(1e-5) * (panel.v1 - panel.v0));
        std::vector<std::uint32_t> lattice(lu.size() * lv.size(), std::numeric_limits<std::uint32_t>::max());
        const auto index_of = [](const std::vector<Real>& values, Real x) {
            const auto it = std::lower_bound(values.begin(), values.end(), x);
            if (it == values.end()) return values.size() - 1;
            if (it != values.begin() && x - *std::prev(it) < *it - x) return static_cast<std::size_t>(std::prev(it) - values.begin());
            return static_cast<std::size_t>(it - values.begin());
        };
        bool complete = std::count(used.begin(), used.end(), 1) == static_cast<std::ptrdiff_t>(lattice.size()) && lv.size() >= 2 && lu.size() >= 2;
        for (std::uint32_t v = 0; v < mesh.vertex_count() && complete; ++v)
            if (used[v]) {
                std::uint32_t& slot = lattice[index_of(lu, mesh.uvs(0, v)) * lv.size() + index_of(lv, mesh.uvs(1, v))];
                complete = slot == std::numeric_limits<std::uint32_t>::max();
                slot = v;
            }
        if (complete) {
            m = static_cast<int>(lv.size());
            const int columns = static_cast<int>(lu.size());
            closed = line_gap(mesh.positions(Eigen::all, std::vector<std::uint32_t>(lattice.begin(), lattice.begin() + m)), 0,
                              mesh.positions(Eigen::all, std::vector<std::uint32_t>(lattice.end() - m, lattice.end())), 0, m) <=
                     Real(1e-4) * std::max<Real>(Real(panel.u1 - panel.u0) * Real(panel.per_u), Real(1));
            n = closed ? columns - 1 : columns;
            if (closed ? n % stride == 0 : (n - 1) % stride == 0) {
                x.resize(3, n * m);
                pin = VectorX::Zero(n * m);
                for (int k = 0; k < n * m; ++k) {
                    x.col(k) = mesh.positions.col(lattice[static_cast<std::size_t>(k)]);
                    if (painted) pin[k] = mesh.pin[lattice[static_cast<std::size_t>(k)]];
                }
                how = "the mesh's own " + std::to_string(n) + " x " + std::to_string(m) + " lattice";
            }
        }
    }

    // Otherwise resampled: each panel's rows at the same shares of its length, its lines
    // spread across each row (a flared panel's lines fan out as the built-in cone's do), a
    // multiple of weft_stride segments each, so that a seam falls on a layer-1 line; the
    // panels then joined side by side where a side edge of one meets a side edge of the next.
    if (how.empty()) {
        double longest = 0;
        for (const Panel& panel : panels) longest = std::max(longest, (panel.v1 - panel.v0) * panel.per_v);
        m = std::max(2, static_cast<int>(std::lround(longest / spacing)) + 1);
        std::vector<PanelGrid> grids;
        for (const Panel& panel : panels) {
            double width = 0;
            for (int k = 0; k < 5; ++k) {
                const auto [lo, hi] = row_span(mesh, panel, panel.v0 + (panel.v1 - panel.v0) * (Real(0.1) + Real(0.2) * Real(k)));
                width += (hi - lo) * panel.per_u / 5;
            }
            const int segments = std::max(stride, static_cast<int>(std::ceil(width / spacing / stride - 0.25)) * stride);
            if (static_cast<long long>(segments + 1) * m > max_garment_particles)
                return fail(p + ".spacing_m: " + number(spacing) + " m gives more than " + std::to_string(max_garment_particles) + " particles");
            grids.push_back(grid_panel(mesh, panel, segments, m, painted));
            if (grids.back().outside > 0)
                return fail(p + ": " + std::to_string(grids.back().outside) + " grid points of " + what + "'s panel " +
                            std::to_string(grids.size() - 1) + " fall outside it: a panel must be one piece across at every level of v "
                            "(straps, holes and slits are not supported yet)");
        }
        // Chain the panels: the next one's first (or, turned, its last) line meets this one's
        // last; then, for an open garment whose first panel is not at an end, the ones before
        // it, each whose last (or, turned, first) line meets the chain's first.
        const Real seam_tolerance = Real(0.25) * spacing;
        std::vector<int> chain = {0};
        std::vector<std::uint8_t> placed(grids.size(), 0);
        placed[0] = 1;
        const auto turn = [&](PanelGrid& g) {
            for (int line = 0; line < g.lines / 2; ++line) {
                g.x.middleCols(line * m, m).swap(g.x.middleCols((g.lines - 1 - line) * m, m));
                g.pin.segment(line * m, m).swap(g.pin.segment((g.lines - 1 - line) * m, m));
            }
        };
        for (bool grew = true; grew;) {
            grew = false;
            const PanelGrid& last = grids[static_cast<std::size_t>(chain.back())];
            for (std::size_t k = 0; k < grids.size() && !grew; ++k) {
                if (placed[k]) continue;
                if (line_gap(grids[k].x, grids[k].lines - 1, last.x, last.lines - 1, m) < seam_tolerance) turn(grids[k]);
                if (line_gap(grids[k].x, 0, last.x, last.lines - 1, m) < seam_tolerance) {
                    chain.push_back(static_cast<int>(k));
                    placed[k] = 1;
                    grew = true;
                }
            }
        }
        for (bool grew = true; grew;) {
            grew = false;
            const PanelGrid& first = grids[static_cast<std::size_t>(chain.front())];
            for (std::size_t k = 0; k < grids.size() && !grew; ++k) {
                if (placed[k]) continue;
                if (line_gap(grids[k].x, 0, first.x, 0, m) < seam_tolerance) turn(grids[k]);
                if (line_gap(grids[k].x, grids[k].lines - 1, first.x, 0, m) < seam_tolerance) {
                    chain.insert(chain.begin(), static_cast<int>(k));
                    placed[k] = 1;
                    grew = true;
                }
            }
        }
        if (chain.size() != grids.size())
            return fail(p + ": " + what + " has " + std::to_string(grids.size()) + " panels, but only " + std::to_string(chain.size()) +
                        " join side by side (a panel's side edge must meet the next one's, row for row)");
        const PanelGrid& first = grids[static_cast<std::size_t>(chain.front())];
        const PanelGrid& last = grids[static_cast<std::size_t>(chain.back())];
        closed = line_gap(first.x, 0, last.x, last.lines - 1, m) < seam_tolerance;
        n = 0;
        for (int k : chain) n += grids[static_cast<std::size_t>(k)].lines - 1;
        if (!closed) ++n;
        x.resize(3, n * m);
        pin = VectorX::Zero(n * m);
        int line = 0;
        for (std::size_t c = 0; c < chain.size(); ++c) {
            const PanelGrid& g = grids[static_cast<std::size_t>(chain[c])];
            const int take = c + 1 == chain.size() && !closed ? g.lines : g.lines - 1;  // a seam's line once
            x.middleCols(line * m, take * m) = g.x.leftCols(take * m);
            pin.segment(line * m, take * m) = g.pin.head(take * m);
            line += take;
        }
        const std::size_t seams = closed ? panels.size() : panels.size() - 1;
        how = "resampled " + std::to_string(n) + " x " + std::to_string(m) + " at " + number(spacing) + " m from " +
              std::to_string(panels.size()) + (panels.size() == 1 ? " panel" : " panels") + " sewn at " + std::to_string(seams) +
              (seams == 1 ? " seam" : " seams");
    }
    if (n < (closed ? 2 * stride : stride + 1))
        return fail(p + ": " + what + " is too narrow for its weft_stride " + std::to_string(stride) + " (" + std::to_string(n) + " lines)");

    // Row 0 at the held edge: the painted one, else the higher.
    Real first = 0, last = 0;
    for (int line = 0; line < n; ++line) {
        first += painted ? pin[line * m] : x(1, line * m);
        last += painted ? pin[line * m + m - 1] : x(1, line * m + m - 1);
    }
    if (last > first)
        for (int line = 0; line < n; ++line)
            for (int row = 0; row < m / 2; ++row) {
                x.col(line * m + row).swap(x.col(line * m + m - 1 - row));
                std::swap(pin[line * m + row], pin[line * m + m - 1 - row]);
            }
    // Lines in the builders' turn: the line step crossed with the row step points into the
    // body (components/garment.hpp; the render triangles then face out).
    const Vec3 centre = x.rowwise().mean();
    Real inward = 0;
    for (int line = 0; line + 1 < n; ++line)
        for (int row = 0; row + 1 < m; ++row) {
            const Vec3 a = x.col(line * m + row);
            const Vec3 across = x.col((line + 1) * m + row) - a, down = x.col(line * m + row + 1) - a;
            Vec3 out = a - centre;
            out.y() = 0;
            inward -= across.cross(down).dot(out);
        }
    if (inward < 0) {
        Matrix3X flipped(3, n * m);
        VectorX flipped_pin(n * m);
        for (int line = 0; line < n; ++line) {
            // A tube keeps its first line; a sheet turns end for end.
            const int from = closed ? (n - line) % n : n - 1 - line;
            flipped.middleCols(line * m, m) = x.middleCols(from * m, m);
            flipped_pin.segment(line * m, m) = pin.segment(from * m, m);
        }
        x = std::move(flipped);
        pin = std::move(flipped_pin);
    }

    MeshGrid out;
    GridGarment& g = out.grid;
    g.warp_lines = n;
    g.particles_per_line = m;
    g.weft_stride = stride;
    g.closed = closed;
    g.grid_positions = std::move(x);
    g.pinned.assign(static_cast<std::size_t>(n * m), 0);
    g.config = params.config;
    g.pin_weights = params.pin_weights;
    int held = 0;
    for (int k = 0; k < n * m; ++k) {
        const bool hold = painted ? pin[k] >= Real(0.5) : (k % m) < params.fitting_rows;
        g.pinned[static_cast<std::size_t>(k)] = hold ? 1 : 0;
        held += hold;
    }
    if (held == 0) return fail(p + ".pins: " + what + "'s COLOR_0 paints no vertex held (red >= 0.5)");
    if (!painted && params.fitting_rows >= m) return fail(p + ".fitting_rows: " + std::to_string(params.fitting_rows) + " of " + std::to_string(m) + " rows");
    out.how = how + (closed ? ", closed" : ", open") + ", " + std::to_string(held) + " particles held (" +
              (painted ? "painted" : "the upper edge") + ")";
    return out;
}

// A derived pattern (see the header): u the angle round the vertical axis through the
// middle of the mesh's box, in metres at its median radius, from a seam in the widest
// angular gap between its vertices (or, closed round, wherever the widest is); v the
// height. A triangle spanning the seam takes copies of its vertices before it, a turn on.
Result<std::string> derive_pattern(GarmentMeshAsset& mesh, std::string_view name) {
    const std::string what = mesh.name.empty() ? "the mesh" : "mesh '" + mesh.name + "'";
    const std::string p(name);
    if (mesh.indices.empty() || mesh.indices.size() % 3 != 0) return fail(p + ": " + what + " has no triangles");
    const auto count = static_cast<std::uint32_t>(mesh.vertex_count());
    std::vector<std::uint8_t> used(count, 0);
    for (const std::uint32_t v : mesh.indices) {
        if (v >= count) return fail(p + ": " + what + " has a triangle on vertex " + std::to_string(v) + " of " + std::to_string(count));
        used[v] = 1;
    }
    Real lo_x = std::numeric_limits<Real>::infinity(), hi_x = -lo_x, lo_z = lo_x, hi_z = -lo_x;
    for (std::uint32_t v = 0; v < count; ++v)
        if (used[v]) {
            lo_x = std::min(lo_x, mesh.positions(0, v)), hi_x = std::max(hi_x, mesh.positions(0, v));
            lo_z = std::min(lo_z, mesh.positions(2, v)), hi_z = std::max(hi_z, mesh.positions(2, v));
        }
    const Real cx = (lo_x + hi_x) / 2, cz = (lo_z + hi_z) / 2;
    constexpr double turn = 2 * std::numbers::pi;
    std::vector<double> angle(count, 0);
    std::vector<Real> radii, sorted;
    for (std::uint32_t v = 0; v < count; ++v) {
        if (!used[v]) continue;
        const double dx = mesh.positions(0, v) - cx, dz = mesh.positions(2, v) - cz;
        angle[v] = std::atan2(dx, dz);
        radii.push_back(static_cast<Real>(std::hypot(dx, dz)));
        sorted.push_back(static_cast<Real>(angle[v]));
    }
    std::sort(sorted.begin(), sorted.end());
    double seam = sorted.back() + (sorted.front() + turn - sorted.back()) / 2, widest = sorted.front() + turn - sorted.back();
    for (std::size_t k = 1; k < sorted.size(); ++k)
        if (sorted[k] - sorted[k - 1] > widest) widest = sorted[k] - sorted[k - 1], seam = (sorted[k] + sorted[k - 1]) / 2.0;
    std::nth_element(radii.begin(), radii.begin() + static_cast<std::ptrdiff_t>(radii.size() / 2), radii.end());
    const double radius = radii[radii.size() / 2];
    if (!(radius > 0)) return fail(p + ": " + what + " has no UVs, and no pattern can be derived: it does not go round a vertical axis");
    // Angles from the seam, in [0, 2 pi).
    for (std::uint32_t v = 0; v < count; ++v)
        if (used[v]) angle[v] = std::fmod(std::fmod(angle[v] - seam, turn) + turn, turn);
    std::vector<std::uint32_t> copy(count, std::numeric_limits<std::uint32_t>::max());
    std::vector<std::uint32_t> copy_of;  // per copy: the vertex it copies
    std::uint32_t next = count;
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        double lo = turn, hi = 0;
        for (std::size_t k = 0; k < 3; ++k) lo = std::min(lo, angle[mesh.indices[t + k]]), hi = std::max(hi, angle[mesh.indices[t + k]]);
        if (hi - lo <= std::numbers::pi) continue;
        for (std::size_t k = 0; k < 3; ++k) {
            const std::uint32_t v = mesh.indices[t + k];
            if (angle[v] >= std::numbers::pi) continue;
            if (copy[v] == std::numeric_limits<std::uint32_t>::max()) copy[v] = next++, copy_of.push_back(v);
            mesh.indices[t + k] = copy[v];
        }
    }
    const std::uint32_t total = next;
    mesh.positions.conservativeResize(3, total);
    if (mesh.pin.size() == count) mesh.pin.conservativeResize(total);
    for (std::uint32_t v = 0; v < count; ++v)
        if (copy[v] != std::numeric_limits<std::uint32_t>::max()) {
            mesh.positions.col(copy[v]) = mesh.positions.col(v);
            if (mesh.pin.size() == total) mesh.pin[copy[v]] = mesh.pin[v];
        }
    mesh.uvs.resize(2, total);
    for (std::uint32_t v = 0; v < total; ++v) {
        const std::uint32_t from = v < count ? v : copy_of[v - count];
        const double a = v < count ? angle[v] : angle[from] + turn;  // a copy: one turn on
        mesh.uvs.col(v) = Eigen::Matrix<Real, 2, 1>(static_cast<Real>(a * radius), mesh.positions(1, from));
    }
    // Seen from its axis the mesh must not fold over itself: its triangles all turn one way.
    std::size_t turned[2] = {0, 0};
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        using Vec2 = Eigen::Matrix<Real, 2, 1>;
        const Vec2 a = mesh.uvs.col(mesh.indices[t]), b = mesh.uvs.col(mesh.indices[t + 1]), c = mesh.uvs.col(mesh.indices[t + 2]);
        const Real area = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
        if (area != 0) ++turned[area > 0 ? 1 : 0];
    }
    const std::size_t fewer = std::min(turned[0], turned[1]), triangles = mesh.indices.size() / 3;
    if (fewer > triangles / 100)
        return fail(p + ": " + what + " has no UVs, and no pattern can be derived: seen from its vertical axis " + std::to_string(fewer) +
                    " of its " + std::to_string(triangles) + " triangles fold back over the others (give it UVs)");
    std::ostringstream line;
    line << what << " has no UVs: its pattern is derived round its vertical axis (u the angle at its median radius "
         << number(std::round(radius * 1000) / 1000) << " m, v the height), ";
    if (total == count)
        line << "open where its widest gap round the axis is (" << number(std::round(widest * 180 / std::numbers::pi)) << " degrees)";
    else
        line << "cut at a seam, " << total - count << " vertices doubled";
    return line.str();
}

Result<std::string> place_on_current_pose(const Registry& registry, Entity character, GarmentPose pose, GarmentMeshAsset& mesh,
                                          std::string_view name) {
    if (pose == GarmentPose::current) return std::string("modelled on the character as it stands");
    const auto* skin = registry.try_get<SkinnedMesh>(character);
    const auto* skeleton = registry.try_get<Skeleton>(character);
    if (!skin || !skin->mesh || skin->mesh->indices.empty() || !skeleton || !skeleton->asset ||
        skeleton->skinning.size() != skeleton->asset->size())
        return fail(std::string(name) + ".modelled_on: the character has no skin and skeleton to place a bind-pose garment by");
    const MeshAsset& body = *skin->mesh;
    const auto* landmarks = registry.try_get<BodyLandmarks>(character);
    const std::optional<TrunkSkin> bind = trunk_skin(body, *skeleton->asset, landmarks, {});
    if (!bind)
        return fail(std::string(name) + ".modelled_on: no skin of the character's trunk to place a bind-pose garment by");
    Real moved = 0;
    for (Eigen::Index v = 0; v < mesh.positions.cols(); ++v) {
        const Eigen::Vector3d p = mesh.positions.col(v).cast<double>();
        // Moved as the closest point of the bind pose's trunk skin is (trunk_skin.hpp).
        Eigen::Matrix<double, 3, 4> blend = Eigen::Matrix<double, 3, 4>::Zero();
        double total = 0;
        for (const BoneInfluence& b : trunk_influences(*bind, body, p)) {
            blend += b.weight * skeleton->skinning[static_cast<std::size_t>(b.bone)].matrix().topRows<3>().cast<double>();
            total += b.weight;
        }
        if (total <= 0) continue;
        const Vec3 placed = (blend / total * p.homogeneous()).cast<Real>();
        moved = std::max(moved, (placed - mesh.positions.col(v)).norm());
        mesh.positions.col(v) = placed;
    }
    std::ostringstream how;
    how.precision(1);
    how << std::fixed << "modelled on the bind pose: placed on the current pose by the trunk's skin weights (moved up to " << 100 * moved
        << " cm)" << (landmarks ? "" : " (no body landmarks: every bone taken as the trunk)");
    return how.str();
}

Result<void> check_garment_units(const GarmentMeshAsset& mesh, Real height_m, std::string_view name) {
    if (!(height_m > 0) || mesh.positions.cols() == 0) return {};
    const Real span = (mesh.positions.rowwise().maxCoeff() - mesh.positions.rowwise().minCoeff()).norm();
    if (span <= garment_units_factor * height_m && span * garment_units_factor >= height_m) return {};
    std::ostringstream what;
    what << name << ": mesh '" << mesh.name << "' spans " << number(span) << " m against a character " << number(height_m)
         << " m tall (" << number(span / height_m) << " times): not in the character's units (model it in them, or scale it)";
    return fail(what.str());
}

GarmentPlacement measure_garment_placement(Registry& registry, Entity character, const GridGarment& grid) {
    GarmentPlacement out;
    struct Body {
        Mat3 to_unit;  // world offset from the centre -> unit sphere
        Vec3 center;
        bool trunk;
    };
    std::vector<Body> bodies;
    for (const Entity e : character_colliders(registry, character)) {
        const auto& c = registry.get<EllipsoidCollider>(e);
        const EllipsoidFrame f = make_ellipsoid_frame(c.world);
        if (c.placed && f.active)
            bodies.push_back({f.to_unit, f.center, c.region == BodyRegion::pelvis || c.region == BodyRegion::torso});
    }
    const auto cells = static_cast<Eigen::Index>(grid.grid_positions.cols());
    if (bodies.empty() || cells == 0 || grid.pinned.size() != static_cast<std::size_t>(cells)) return out;
    const auto* transform = registry.try_get<Transform>(character);
    const Affine3 to_world = transform ? transform->matrix() : Affine3::Identity();
    std::size_t inside = 0;
    std::vector<Real> held;
    Vec3 held_center = Vec3::Zero();
    for (Eigen::Index k = 0; k < cells; ++k) {
        const Vec3 p = to_world * Vec3(grid.grid_positions.col(k));
        // The radial distance from the nearest ellipsoid's surface (0 inside), and the depth
        // in the deepest one (its unit sphere's radius through the point).
        Real nearest = std::numeric_limits<Real>::infinity(), deepest = nearest;
        for (const Body& b : bodies) {
            const Real s = (b.to_unit * (p - b.center)).norm();
            nearest = std::min(nearest, s <= 1 ? Real(0) : (p - b.center).norm() * (1 - 1 / s));
            deepest = std::min(deepest, s);
        }
        inside += deepest < 1 - garment_inside_depth ? 1 : 0;
        if (grid.pinned[static_cast<std::size_t>(k)]) held.push_back(nearest), held_center += p;
    }
    out.inside_share = Real(inside) / Real(cells);
    if (held.empty()) return out;
    held_center /= Real(held.size());
    std::nth_element(held.begin(), held.begin() + static_cast<std::ptrdiff_t>(held.size() / 2), held.end());
    out.held_distance_m = held[held.size() / 2];
    if (!grid.closed || grid.warp_lines < 3 || grid.particles_per_line < 1) return out;
    // Round the body: the turns its held edge (each line's highest held point, in line order)
    // makes, seen from above, about the centre of the trunk's ellipsoid nearest the held points.
    const Body* axis = nullptr;
    for (const Body& b : bodies)
        if (!axis || (b.trunk && !axis->trunk) ||
            (b.trunk == axis->trunk && (b.center - held_center).squaredNorm() < (axis->center - held_center).squaredNorm()))
            axis = &b;
    std::vector<Vec3> edge;
    const auto m = static_cast<std::size_t>(grid.particles_per_line);
    for (std::size_t line = 0; line < static_cast<std::size_t>(grid.warp_lines); ++line)
        for (std::size_t row = 0; row < m; ++row)
            if (grid.pinned[line * m + row]) {
                edge.push_back(to_world * Vec3(grid.grid_positions.col(static_cast<Eigen::Index>(line * m + row))) - axis->center);
                break;
            }
    Real turned = 0;
    for (std::size_t i = 0; i < edge.size(); ++i) {
        const Vec3& a = edge[i];
        const Vec3& b = edge[(i + 1) % edge.size()];
        turned += std::atan2(a.z() * b.x() - a.x() * b.z(), a.x() * b.x() + a.z() * b.z());
    }
    out.turns_round_body = std::abs(turned) / (2 * std::numbers::pi_v<Real>);
    return out;
}

Result<void> check_garment_placement(Registry& registry, Entity character, const GridGarment& grid, std::string_view mesh_name,
                                     std::string_view name) {
    const GarmentPlacement placed = measure_garment_placement(registry, character, grid);
    std::ostringstream what;
    what.precision(2);
    what << name << ": mesh '" << mesh_name << "' ";
    if (placed.inside_share > garment_inside_share) {
        what << "lies inside the body (" << number(std::round(100 * placed.inside_share)) << " % of it deeper than "
             << number(100 * garment_inside_depth) << " % into the body's ellipsoids; at most " << number(100 * garment_inside_share)
             << " %): model it over the body";
        return fail(what.str());
    }
    if (placed.turns_round_body < Real(0.5)) {
        what << "is closed round, but its held edge does not go round the body (" << std::fixed << placed.turns_round_body
             << " turns round the trunk): model it around the character";
        return fail(what.str());
    }
    const auto* c = registry.try_get<Character>(character);
    if (c && c->height_m > 0 && placed.held_distance_m > garment_far_fraction * c->height_m) {
        what << "is held " << std::fixed << placed.held_distance_m << " m from the body (the median of its held points; at most "
             << number(100 * garment_far_fraction) << " % of the character's height, " << garment_far_fraction * c->height_m
             << " m): model it on the body";
        return fail(what.str());
    }
    return {};
}

Result<Entity> attach_mesh_garment(Registry& registry, Entity character, const GarmentMeshAsset& authored, const MeshGarmentParams& params,
                                   std::string_view name) {
    if (const auto* c = registry.try_get<Character>(character))
        if (auto units = check_garment_units(authored, c->height_m, name); !units) return std::unexpected(units.error());
    GarmentMeshAsset mesh = authored;
    if (mesh.uvs.cols() != mesh.positions.cols())
        if (auto pattern = derive_pattern(mesh, name); !pattern) return std::unexpected(pattern.error());
    if (auto placed = place_on_current_pose(registry, character, params.modelled_on, mesh, name); !placed)
        return std::unexpected(placed.error());
    auto grid = grid_from_mesh(mesh, params, name);
    if (!grid) return std::unexpected(grid.error());
    if (auto placed = check_garment_placement(registry, character, grid->grid, authored.name, name); !placed)
        return std::unexpected(placed.error());
    auto garment = attach_grid_garment(registry, character, grid->grid, name);
    if (!garment) return garment;
    // Drawn as authored: the mesh itself, carried by the grid's particles.
    registry.emplace_or_replace(*garment, embed_surface(mesh, grid->grid, *registry.get<Garment>(*garment).fabric));
    return garment;
}

Result<Entity> attach_garment_file(Registry& registry, Entity character, const std::filesystem::path& file, std::string_view mesh_name,
                                   const MeshGarmentParams& params, std::string_view name) {
    auto mesh = import_garment_mesh(file, mesh_name);
    if (!mesh) return std::unexpected(mesh.error());
    return attach_mesh_garment(registry, character, *mesh, params, name);
}

Result<GarmentMeshAsset> garment_mesh_of_character(const CharacterAsset& asset, std::string_view mesh_name,
                                                   std::span<const std::size_t> modelled, std::string_view name,
                                                   std::vector<std::size_t>* used) {
    const std::string file = asset.source.string();
    std::string names;
    for (const MeshInfo& info : asset.meshes)
        if (names.find("'" + info.name + "'") == std::string::npos) names.append(names.empty() ? "" : ", ").append("'" + info.name + "'");
    std::vector<std::size_t> chosen;
    std::string label(mesh_name);
    if (mesh_name.empty()) {
        if (modelled.size() != 1) {
            std::string found;
            for (const std::size_t k : modelled) found.append(found.empty() ? "" : ", ").append("'" + asset.meshes.at(k).name + "'");
            return fail(std::string(name) + ": " + file + " holds " + (modelled.empty() ? "no modelled garment" : found) +
                        ": name the mesh to simulate as " + file + ":MESH (meshes: " + names + ")");
        }
        label = asset.meshes.at(modelled.front()).name;
    }
    for (std::size_t k = 0; k < asset.meshes.size(); ++k)
        if (asset.meshes[k].name == label) chosen.push_back(k);
    if (chosen.empty()) return fail(std::string(name) + ": " + file + ": no mesh named '" + label + "' (meshes: " + names + ")");
    const MeshAsset& mesh = *asset.mesh;
    GarmentMeshAsset out;
    out.name = label;
    std::size_t total = 0;
    for (const std::size_t k : chosen) {
        total += asset.meshes[k].vertex_count;
    }
    out.positions.resize(3, static_cast<Eigen::Index>(total));
    // A part without UVs leaves the whole mesh without (a pattern is derived for it).
    const bool uvs = mesh.uvs.cols() == mesh.bind_positions.cols() &&
                     std::all_of(chosen.begin(), chosen.end(), [&](std::size_t k) { return asset.meshes[k].has_uvs; });
    if (uvs) out.uvs.resize(2, static_cast<Eigen::Index>(total));
    Eigen::Index at = 0;
    for (const std::size_t k : chosen) {
        const MeshInfo& info = asset.meshes[k];
        const Eigen::Index first = info.first_vertex, count = info.vertex_count;
        out.positions.middleCols(at, count) = mesh.bind_positions.middleCols(first, count);
        if (uvs) out.uvs.middleCols(at, count) = mesh.uvs.middleCols(first, count);
        if (k < mesh.submeshes.size()) {
            const Submesh& sub = mesh.submeshes[k];
            for (std::uint32_t i = sub.first_index; i < sub.first_index + sub.index_count; ++i)
                out.indices.push_back(static_cast<std::uint32_t>(mesh.indices[i] - static_cast<std::uint32_t>(first) + static_cast<std::uint32_t>(at)));
        }
        at += count;
    }
    if (out.indices.empty()) return fail(std::string(name) + ": mesh '" + label + "' of " + file + " has no triangles");
    if (used) *used = chosen;
    return out;
}

GarmentMeshAsset garment_as_mesh(Registry& registry, Entity garment) {
    const Garment& g = registry.get<Garment>(garment);
    const Fabric& f = *g.fabric;
    const auto n = static_cast<int>(f.warp_lines), m = static_cast<int>(f.particles_per_line);
    const int columns = f.closed ? n + 1 : n;
    const auto* transform = registry.try_get<Transform>(g.body.character);
    const Affine3 to_model = transform ? Affine3(transform->matrix().inverse()) : Affine3::Identity();
    std::vector<std::uint8_t> held(f.particle_count(), 0);
    for (const PinBinding& pin : g.state.pins) held[pin.particle] = 1;
    GarmentMeshAsset mesh;
    mesh.name = "Garment";
    mesh.positions.resize(3, columns * m);
    mesh.uvs.resize(2, columns * m);
    mesh.pin.resize(columns * m);
    for (int column = 0; column < columns; ++column)
        for (int row = 0; row < m; ++row) {
            const std::uint32_t particle = f.grid[static_cast<std::size_t>((column % n) * m + row)];
            const int v = column * m + row;
            mesh.positions.col(v) = to_model * Vec3(f.rest_shape.col((column % n) * m + row));
            mesh.uvs.col(v) = Eigen::Vector2f(Real(column) / Real(f.closed ? n : n - 1), Real(row) / Real(m - 1));
            mesh.pin[v] = held[particle] ? 1 : 0;
        }
    // Two triangles a quad, facing out as the garment's own (components/garment.hpp).
    for (int column = 0; column + 1 < columns; ++column)
        for (int row = 0; row + 1 < m; ++row) {
            const auto a = static_cast<std::uint32_t>(column * m + row), b = a + static_cast<std::uint32_t>(m);
            mesh.indices.insert(mesh.indices.end(), {a, a + 1, b, b, a + 1, b + 1});
        }
    return mesh;
}

}  // namespace drape
