// The garment parameter table; see garment_parameters.hpp.
//
// Ranges are the builder's: every value in them builds a garment that steps with finite
// values (the edges were tried on the walking body of the cloth tests). The upper bounds
// keep float arithmetic, not the cloth, from deciding what happens (docs/robustness.md).
#include "drape/systems/cloth/garment_parameters.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <type_traits>

namespace drape {

bool ParameterRange::contains(double value) const noexcept {
    if (std::isnan(value)) return false;
    if (min_open ? value <= min : value < min) return false;
    if (max_open ? value >= max : value > max) return false;
    return true;
}

std::string ParameterRange::text() const {
    std::string s = min_open ? "(" : "[";
    s += parameter_number_text(min);
    s += ", ";
    s += parameter_number_text(max);
    s += max_open ? ")" : "]";
    return s;
}

std::string ParameterSpec::range_text() const {
    if (kind == ParameterKind::integer) return "integer " + range.text();
    std::string s = range.text();
    if (!unit.empty()) {
        s += ' ';
        s += unit;
    }
    return s;
}

bool GarmentParameterSpec::in_material() const noexcept {
    return std::holds_alternative<int ClothMaterial::*>(member) || std::holds_alternative<Real ClothMaterial::*>(member);
}

std::string GarmentParameterSpec::field() const {
    std::string s = in_material() ? "material." : "";
    s += name;
    return s;
}

double GarmentParameterSpec::get(const TubeParams& params) const {
    return std::visit(
        [&](auto pointer) -> double {
            if constexpr (std::is_same_v<decltype(pointer), int ClothMaterial::*> ||
                          std::is_same_v<decltype(pointer), Real ClothMaterial::*>)
                return static_cast<double>(params.material.*pointer);
            else
                return static_cast<double>(params.*pointer);
        },
        member);
}

double GarmentParameterSpec::get(const ClothMaterial& material) const {
    if (const auto* p = std::get_if<Real ClothMaterial::*>(&member)) return static_cast<double>(material.**p);
    if (const auto* p = std::get_if<int ClothMaterial::*>(&member)) return static_cast<double>(material.**p);
    return std::numeric_limits<double>::quiet_NaN();  // not a material field: never in range
}

void GarmentParameterSpec::set(TubeParams& params, double value) const {
    std::visit(
        [&](auto pointer) {
            using Pointer = decltype(pointer);
            if constexpr (std::is_same_v<Pointer, int TubeParams::*>)
                params.*pointer = static_cast<int>(std::lround(value));
            else if constexpr (std::is_same_v<Pointer, Real TubeParams::*>)
                params.*pointer = static_cast<Real>(value);
            else if constexpr (std::is_same_v<Pointer, int ClothMaterial::*>)
                params.material.*pointer = static_cast<int>(std::lround(value));
            else
                params.material.*pointer = static_cast<Real>(value);
        },
        member);
}

namespace {

// Rows are built through these two, so that a row's kind always matches its field's type.
template <class Owner>
GarmentParameterSpec integer(std::string_view name, int Owner::*field, ParameterRange range, std::string_view description) {
    return GarmentParameterSpec{{name, ParameterKind::integer, range, "", description}, field};
}
template <class Owner>
GarmentParameterSpec real(std::string_view name, Real Owner::*field, ParameterRange range, std::string_view unit,
                          std::string_view description) {
    return GarmentParameterSpec{{name, ParameterKind::real, range, unit, description}, field};
}

// A row a garment from a file takes too (GarmentParameterSpec::file_garments).
GarmentParameterSpec for_file_garments(GarmentParameterSpec spec) {
    spec.file_garments = true;
    return spec;
}

ParameterRange closed(double min, double max) { return {min, max, false, false}; }
ParameterRange open_min(double min, double max) { return {min, max, true, false}; }  // (min, max]
ParameterRange open_max(double min, double max) { return {min, max, false, true}; }  // [min, max)

// Grid sides: the builder's limit per side (build_grid_topology); together at most
// max_garment_particles.
constexpr int max_side = 4096;

}  // namespace

std::span<const GarmentParameterSpec> garment_parameters() {
    static const GarmentParameterSpec table[] = {
        integer("warp_lines", &TubeParams::warp_lines, closed(2, max_side),
                "lines around the body; a multiple of `weft_stride`"),
        integer("particles_per_line", &TubeParams::particles_per_line, closed(2, max_side),
                "particles down each line; `warp_lines` x `particles_per_line` is at most the `particles` limit"),
        for_file_garments(integer("weft_stride", &TubeParams::weft_stride, closed(1, max_side - 1),
                                  "every n-th line is integrated, the lines between are placed (method §3.2); less than `warp_lines`")),
        real("line_spacing_m", &TubeParams::line_spacing_m, closed(0, 1), "m",
             "> 0: on a wider body more lines, at most this far apart round the ring (never fewer than `warp_lines`); 0: `warp_lines` as given"),
        real("hem_spacing_leg_widths", &TubeParams::hem_spacing_leg_widths, closed(0, 100), "",
             "> 0: more lines where neighbouring layer-1 lines at the hem would stand farther apart than this x the thinner leg's width at the hem's height (never fewer than `warp_lines`); 0: no limit"),
        real("length_m", &TubeParams::length_m, open_min(0, 10), "m", "from the ring to the hem, along the cloth"),
        real("hem_clearance_fraction", &TubeParams::hem_clearance_fraction, open_max(0, 1), "",
             "the hem stays at least this x body height above the body's lowest point: `length_m` is shortened on a shorter body (0: never)"),
        real("flare_deg", &TubeParams::flare_deg, closed(0, 80), "deg", "cone half-angle from vertical"),
        real("ease_m", &TubeParams::ease_m, closed(0, 1), "m", "gap between the body outline at the ring and the cloth"),
        real("ring_height_fraction", &TubeParams::ring_height_fraction, open_max(0, 1), "",
             "> 0: ring height / body height (used when `ring_height_m` is 0); 0: at the body's waist for a skirt, under the arms for a dress"),
        real("ring_height_m", &TubeParams::ring_height_m, closed(0, 10), "m",
             "> 0: ring height above the body's lowest point (0: from `ring_height_fraction`)"),
        real("torso_radius_fraction", &TubeParams::torso_radius_fraction, open_min(0, 1), "",
             "colliders farther from the body axis than this x body height (arms) are not part of the outline at the ring"),
        for_file_garments(integer("fitting_rows", &TubeParams::fitting_rows, closed(1, max_side - 1),
                                  "rows pinned to the body (method §3.5); fewer than `particles_per_line`")),
        for_file_garments(real("inertia_linear", &TubeParams::inertia_linear, closed(0, 1), "",
                               "how much of the body's linear acceleration the cloth feels (method §3.3's -m a_body): 1 physical, 0 carried rigidly")),
        for_file_garments(real("inertia_angular", &TubeParams::inertia_angular, closed(0, 1), "",
                               "how much of the body's turning the cloth feels (centrifugal, Coriolis): 1 physical, 0 carried rigidly")),
        for_file_garments(real("inertia_max_linear_m_s2", &TubeParams::inertia_max_linear_m_s2, closed(0, 1e4), "m/s^2",
                               "> 0: the most of the body's linear acceleration the cloth feels (x `inertia_linear`); beyond it the rest is carried rigidly (an animated jump stopping dead at its top); 0: no bound")),
        for_file_garments(real("inertia_max_fall_m_s2", &TubeParams::inertia_max_fall_m_s2, closed(0, 1e4), "m/s^2",
                               "> 0: the fastest downward acceleration of the body the cloth feels, along gravity (9.81: free fall, which no body that only pushes on the ground outruns); the downward part beyond it is carried rigidly; 0: no bound, the whole -m a of method §3.3")),
        for_file_garments(real("max_distance_share", &TubeParams::max_distance_share, closed(0, 10), "",
                               "> 0: each particle stays within this x the rest length of its line up to its pin of where it hangs in the rest shape, carried by the body (a max distance, as Unity Cloth's; 1: the hem swings up to 60 degrees, never past its pins); 0: none")),
        for_file_garments(integer("max_distance_on_skin", &TubeParams::max_distance_on_skin, closed(0, 1),
                                  "with `max_distance_share`, 1: each sphere's centre is the particle's rest place carried by the skin of the trunk and legs nearest it (a raised thigh carries it, as skinned constraints do); 0: carried by the anchor (the pelvis)")),
        real("thin_trunk_piece_m", &TubeParams::thin_trunk_piece_m, closed(0, 1), "m",
             "> 0: no collision with the torso's and pelvis's ellipsoids whose smallest radius is at most this (pieces that stand between neighbouring particles and hold the cloth open; the anchor's kept); 0: with every ellipsoid"),
        real("areal_density_kg_m2", &ClothMaterial::areal_density_kg_m2, open_min(0, 10), "kg/m^2",
             "mass per area of the cloth (cotton 0.1-0.2, denim 0.3-0.45)"),
        real("stretch_N_m", &ClothMaterial::stretch_N_m, open_min(0, 1e7), "N/m",
             "stretch modulus of warp and weft: force per unit width per unit strain (method §3.3)"),
        real("shear_N_m", &ClothMaterial::shear_N_m, closed(0, 1e7), "N/m", "shear springs' modulus (classic model only)"),
        real("bend_N_m", &ClothMaterial::bend_N_m, closed(0, 1e7), "N/m", "bend springs' modulus (the classic model; the simplified one with `weft_bend`)"),
        real("drag_N_s_m3", &ClothMaterial::drag_N_s_m3, closed(0, 100), "N s/m^3",
             "air drag per area per speed: a particle's k of method §3.3 is this x its area"),
        real("friction", &ClothMaterial::friction, closed(0, 10), "", "Coulomb friction coefficient of the cloth on the body"),
        real("strain_limit", &ClothMaterial::strain_limit, open_min(0, 10), "",
             "Provot's largest relative over-stretch (method §4.1); 0.1 = 10 %"),
        real("compression_limit", &ClothMaterial::compression_limit, closed(0, 1), "",
             "the shortest a spring may become over its rest length, the cloth's folds being coarser than its grid; 0 = none"),
        real("limit_share", &ClothMaterial::limit_share, open_min(0, 1), "",
             "the share of `strain_limit` within which the warp and weft limits hold a spring each substep (the rest is left to the collision after them); at 1 a spring below Provot's limit is the stretch modulus's alone"),
        integer("iterations", &ClothMaterial::iterations, closed(1, 100),
                "constraint and collision rounds per substep (Gauss-Seidel)"),
        integer("weft_bend", &ClothMaterial::weft_bend, closed(0, 1),
                "simplified model, 1: bend springs along its weft rows (each particle to the second beside it) at `bend_N_m`, so that the rows keep the cut's flare ([cloth.md](cloth.md), \"Weft bending\"); 0: the paper's stretch springs only"),
        integer("line_iterations", &ClothMaterial::line_iterations, closed(1, 100),
                "warp lines solved directly (`warp_solve` lines): the most Newton steps of each line solve in a round; more are taken while a spring is off its solution by over `line_tolerance`"),
        real("line_tolerance", &ClothMaterial::line_tolerance, closed(0, 1), "",
             "warp lines solved directly: the residual strain (a spring's distance from its solution over its rest length) below which a line solve stops"),
        real("candidate_margin_m", &ClothMaterial::candidate_margin_m, open_min(0, 1), "m",
             "candidate lists: reach beyond an ellipsoid's surface (method §5)"),
    };
    return table;
}

std::span<const MaterialPreset> material_presets() {
    // Woven fabrics: areal density as sold (g/m^2), stretch moduli of the order a strip test
    // gives for a woven cloth (force per width per strain), drag per area for still air
    // around a moving garment (0.5 rho_air C_d |v| at about half a metre per second).
    static const MaterialPreset presets[] = {
        {"silk", "light and flowing: 60 g/m^2 charmeuse",
         ClothMaterial{.areal_density_kg_m2 = Real(0.06), .stretch_N_m = 800, .shear_N_m = 30, .bend_N_m = 2,
                       .drag_N_s_m3 = Real(0.3), .friction = Real(0.25)}},
        {"cotton", "the default: 170 g/m^2 poplin", ClothMaterial{}},
        {"denim", "heavy and stiff: 400 g/m^2 twill",
         ClothMaterial{.areal_density_kg_m2 = Real(0.4), .stretch_N_m = 8000, .shear_N_m = 600, .bend_N_m = 80,
                       .drag_N_s_m3 = Real(0.3), .friction = Real(0.5)}},
    };
    return presets;
}

Result<ClothMaterial> material_preset(std::string_view name) {
    std::string names;
    for (const MaterialPreset& p : material_presets()) {
        if (p.name == name) return p.material;
        names += (names.empty() ? "" : ", ") + std::string(p.name);
    }
    return fail("material \"" + std::string(name) + "\": no such preset (presets: " + names + ")");
}

const GarmentParameterSpec* find_garment_parameter(std::string_view name) {
    const auto table = garment_parameters();
    const auto it = std::find_if(table.begin(), table.end(), [&](const GarmentParameterSpec& s) { return s.name == name; });
    return it == table.end() ? nullptr : &*it;
}

std::string parameter_number_text(double value) {
    if (!std::isfinite(value)) {
        std::ostringstream s;
        s << value;
        return s.str();
    }
    if (value == std::trunc(value) && std::abs(value) < 1e6) return std::to_string(static_cast<long long>(value));
    // The fewest digits that read back as the same number; a value a Real holds exactly (a
    // default) reads back as that Real: 0.55f is "0.55", not "0.550000012".
    const bool single = std::abs(value) <= double(std::numeric_limits<Real>::max()) &&
                        static_cast<double>(static_cast<Real>(value)) == value;
    char text[32] = {};
    for (int digits = 1; digits <= 17; ++digits) {
        std::snprintf(text, sizeof text, "%.*g", digits, value);
        const double back = std::strtod(text, nullptr);
        if (single ? static_cast<Real>(back) == static_cast<Real>(value) : back == value) break;
    }
    // "1e+07" -> "1e7", "1.5e-05" -> "1.5e-5".
    std::string s = text;
    if (const std::size_t e = s.find('e'); e != std::string::npos) {
        std::string exponent = s.substr(e + 1);
        const bool negative = !exponent.empty() && exponent[0] == '-';
        if (!exponent.empty() && (exponent[0] == '+' || exponent[0] == '-')) exponent.erase(0, 1);
        exponent.erase(0, std::min(exponent.find_first_not_of('0'), exponent.size() - 1));
        s = s.substr(0, e + 1) + (negative ? "-" : "") + exponent;
    }
    return s;
}

}  // namespace drape
