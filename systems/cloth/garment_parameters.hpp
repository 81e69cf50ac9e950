// The garment parameter table: every numeric parameter of a skirt or a dress (the fields of
// TubeParams and of its ClothMaterial) with its kind, range, unit and meaning, written
// once. It drives:
//   - validate(TubeParams) and validate(ClothMaterial) (systems/cloth/garment_builder.hpp),
//     whose messages name the field: "skirt.length_m: must be in (0, 10] m, got -1";
//   - the garment fields of scene files and their checks, and the mapping from a scene's
//     garment onto TubeParams (game/scene_garment_parameters.hpp);
//   - the parameter list in docs/scenes.md (`drape scene-parameters` prints it; a test
//     fails when the two differ).
// A range is per field. What depends on two fields (warp_lines a multiple of weft_stride,
// weft_stride below warp_lines, fitting_rows below particles_per_line, at most
// max_garment_particles in all) validate(TubeParams) checks after the table.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <variant>

#include "drape/components/garment.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/systems/cloth/garment_builder.hpp"

namespace drape {

/// Whether a parameter holds a real number or an integer.
enum class ParameterKind : std::uint8_t { real, integer };

/// An interval of accepted values; each end is closed (the end is accepted) or open.
struct ParameterRange {
    double min = 0;
    double max = 0;
    bool min_open = false;  ///< true: `min` itself is outside, "(min, ...".
    bool max_open = false;  ///< true: `max` itself is outside, "..., max)".

    /// Whether `value` lies in the range (NaN never does).
    [[nodiscard]] bool contains(double value) const noexcept;
    /// "(0, 10]", "[1, 4095]", "(0, 1e7]".
    [[nodiscard]] std::string text() const;
};

/// What a numeric parameter accepts and means, apart from where it is stored.
struct ParameterSpec {
    std::string_view name;          ///< As a scene file and the docs spell it (snake_case, unit suffix).
    ParameterKind kind = ParameterKind::real;
    ParameterRange range;
    std::string_view unit;          ///< "m", "deg", "kg", "N/m", "N s/m"; empty: none.
    std::string_view description;   ///< One line of Markdown (docs/scenes.md).

    /// "(0, 10] m", "integer [2, 4096]": the range as the docs print it.
    [[nodiscard]] std::string range_text() const;
};

/// Where a garment parameter is stored: a field of TubeParams, or of its ClothMaterial.
using GarmentParameterMember =
    std::variant<int TubeParams::*, Real TubeParams::*, int ClothMaterial::*, Real ClothMaterial::*>;

/// One row of the table: a parameter and the field it sets.
struct GarmentParameterSpec : ParameterSpec {
    GarmentParameterMember member;
    /// True where a garment from a file (docs/garments.md) takes the parameter too: how its
    /// grid is integrated and held, and how it moves; not a built-in tube's shape or the
    /// colliders its builder leaves out. Every material field is taken: see takes_file_garments().
    bool file_garments = false;

    /// True for the fields of TubeParams::material.
    [[nodiscard]] bool in_material() const noexcept;
    /// Whether a garment from a file takes the parameter: file_garments or a material field.
    [[nodiscard]] bool takes_file_garments() const noexcept { return file_garments || in_material(); }
    /// The field as the builder's messages name it: "length_m", "material.areal_density_kg_m2".
    [[nodiscard]] std::string field() const;
    /// The field's value in `params`.
    [[nodiscard]] double get(const TubeParams& params) const;
    /// The field's value in `material`; only for in_material() rows.
    [[nodiscard]] double get(const ClothMaterial& material) const;
    /// Sets the field in `params` (an integer field takes the nearest integer). No check:
    /// validate(TubeParams) checks the result.
    void set(TubeParams& params, double value) const;
};

/// The table, in the order the docs list it.
[[nodiscard]] std::span<const GarmentParameterSpec> garment_parameters();

/// A cloth by name, for scene files ("material": "denim") and C++.
struct MaterialPreset {
    std::string_view name;
    std::string_view description;
    ClothMaterial material;
};

/// The presets: silk, cotton (the default ClothMaterial), denim.
[[nodiscard]] std::span<const MaterialPreset> material_presets();

/// The preset called `name`; the error lists the presets there are.
[[nodiscard]] Result<ClothMaterial> material_preset(std::string_view name);

/// The row called `name`, or null.
[[nodiscard]] const GarmentParameterSpec* find_garment_parameter(std::string_view name);

/// A bound or a default as a person writes it: "0", "250000", "0.55", "1e7".
[[nodiscard]] std::string parameter_number_text(double value);

}  // namespace drape
