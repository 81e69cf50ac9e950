// Garments from files (docs/garments.md): a mesh an artist modelled on a character turned
// into the paper's particle grid (method §3.2), and the built-in garments written back as
// such meshes.
//
// The grid comes from the mesh's pattern (UV) space: u across the grain (the weft), v along
// it (the warp). A mesh of one panel whose vertices already form a u x v lattice is used as
// it is (the files `drape export-garment` writes). Any other is resampled, panel by panel
// (a panel: a connected piece of the mesh): rows at the same shares of each panel's v
// extent, `spacing_m` apart on the longest; across each row, the panel's lines spread
// evenly from its one edge to the other at that level (a flared piece's lines fan out, as
// the built-in cone's do), a multiple of weft_stride segments, `spacing_m` apart on its
// mean width; each grid point placed on the surface through the UV triangle that holds it.
// The panels are then sewn side by side into one grid, each where one of its side edges
// meets the previous one's on the surface, row for row; where the last meets the first,
// the weft closes round the body. Row 0 is the held edge.
//
// Where it is held: painted (COLOR_0's red >= 0.5, read at each grid point through its
// triangle), or else the v-edge that lies higher on the body, its `fitting_rows` rows.
//
// The pose it was modelled on: as the character stands when the garment is put on, or its
// bind pose (as an artist models on a character in Blender), then first placed on the
// current pose by the skin's weights: each vertex moved as the closest point of the bind
// pose's trunk skin is (the influences of its triangle's vertices on the trunk's bones,
// blended by the point's barycentric weights). The trunk, not the limbs: a skirt between the
// legs or a cape beside an arm is carried by the hips and the spine, and the cloth then
// finds the limbs where they are.
//
// A mesh without UVs gets a pattern derived from its shape (derive_pattern): u round the
// body's vertical axis, v the height, as a tube or a sheet wrapped round the body is cut;
// one that folds back over itself seen from that axis is refused.
//
// Not yet: panels that a level of v crosses twice (straps, slits, holes), panels sewn
// other than side by side (a yoke, a gusset), and meshes without UVs that cannot be
// derived so (which would need the classic model on their own edges); each is refused with
// one line that says so.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "drape/components/garment.hpp"
#include "drape/engine/assets/character_asset.hpp"
#include "drape/engine/assets/garment_file.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/cloth/garment_builder.hpp"

namespace drape {

/// Where a garment from a mesh is held.
enum class PinSource : std::uint8_t {
    file,       ///< Painted where the file paints (COLOR_0), else automatic.
    painted,    ///< Painted; a file without COLOR_0 is an error.
    automatic,  ///< The higher v-edge's `fitting_rows` rows, whatever the file paints.
};

/// The pose a garment's mesh was modelled on.
enum class GarmentPose : std::uint8_t {
    current,  ///< The character as it stands when the garment is put on: used as it is.
    bind,     ///< The character's bind pose: placed on its current pose by the trunk's skin weights.
};

/// How a mesh becomes a grid, and the cloth it is.
struct MeshGarmentParams {
    Real spacing_m = 0;        ///< Between warp lines and weft rows; 0: the mesh's own lattice where it is one, else 0.029 m.
    int weft_stride = 3;       ///< Every weft_stride-th line is layer 1 (method §3.2).
    PinSource pins = PinSource::file;
    int fitting_rows = 1;      ///< Rows held when the pins are automatic.
    GarmentPose modelled_on = GarmentPose::current;
    GarmentConfig config;      ///< Model, integrator, collision, material, inertia, colour.
    PinWeights pin_weights = PinWeights::nearest_vertex;  ///< How the held particles are bound to the skin.
};

/// The grid `mesh` gives (see above), in the mesh's space, and one line on how it was made
/// ("a 27 x 31 lattice of the mesh's own vertices, closed, 27 particles painted").
struct MeshGrid {
    GridGarment grid;
    std::string how;
};

/// Gives `mesh`, which has no UVs, a pattern: u the angle round the vertical (y) axis
/// through the middle of its box, in metres at the vertices' median distance from it,
/// starting at a seam in the widest angular gap between its vertices (a mesh closed round
/// is cut there: the triangles across it take copies of their vertices, one turn on); v
/// the height. Returns one line saying so; fails, prefixed with `name`, where seen from
/// that axis more than 1 % of its triangles fold back over the others (a sleeve, a
/// collar turned down), or it has no triangles.
[[nodiscard]] Result<std::string> derive_pattern(GarmentMeshAsset& mesh, std::string_view name);

/// Turns `mesh` into a grid; errors are prefixed with `name`.
[[nodiscard]] Result<MeshGrid> grid_from_mesh(const GarmentMeshAsset& mesh, const MeshGarmentParams& params, std::string_view name);

/// Moves `mesh` (in `character`'s model space) from the pose it was modelled on to the
/// character's current pose (see above; nothing moves for GarmentPose::current). Returns one
/// line on what it did; errors are prefixed with `name` (the bind pose asked of a character
/// without skin, skeleton or trunk).
[[nodiscard]] Result<std::string> place_on_current_pose(const Registry& registry, Entity character, GarmentPose pose,
                                                        GarmentMeshAsset& mesh, std::string_view name);

/// A garment mesh spanning more than this many times its character's height, or less than
/// its height over this, is taken to be in other units (centimetres against metres: 100x).
inline constexpr Real garment_units_factor = 10;

/// Fails, prefixed with `name` and naming the mesh, when `mesh` (the diagonal of its box)
/// spans more than garment_units_factor times `height_m` or less than `height_m` over it;
/// no check where `height_m` is not positive.
[[nodiscard]] Result<void> check_garment_units(const GarmentMeshAsset& mesh, Real height_m, std::string_view name);

/// Where a gridded garment lies on its character as it is put on (world space, against the
/// character's ellipsoids).
struct GarmentPlacement {
    Real inside_share = 0;      ///< Share of its particles deeper than garment_inside_depth into an ellipsoid.
    Real held_distance_m = 0;   ///< Median distance of its held particles from the nearest ellipsoid's surface.
    Real turns_round_body = 1;  ///< Closed round: turns its held edge makes round the trunk, seen from above (1 when open).
};
[[nodiscard]] GarmentPlacement measure_garment_placement(Registry& registry, Entity character, const GridGarment& grid);

/// A particle deeper into an ellipsoid than this share of the way from its surface to its
/// centre is inside the body; a garment with more than garment_inside_share of its
/// particles inside is refused. Cut for the character (`drape make-garments`, 8 characters x
/// 4 garments), the most was 13 % (a cape on the Alien).
inline constexpr Real garment_inside_depth = Real(0.3);
inline constexpr Real garment_inside_share = Real(0.5);
/// A garment whose held points lie (median) further than this share of its character's
/// height from the body is refused. Cut for the character, the most was 3.4 % (the cape
/// on the default avatar).
inline constexpr Real garment_far_fraction = Real(0.1);

/// Fails, prefixed with `name` and naming the mesh, when the gridded garment lies inside
/// the body, is closed round but its held edge does not go round the trunk, or is held far
/// from the body (measure_garment_placement against the constants above).
[[nodiscard]] Result<void> check_garment_placement(Registry& registry, Entity character, const GridGarment& grid,
                                                   std::string_view mesh_name, std::string_view name);

/// `mesh` (in `character`'s model space, modelled on the pose params.modelled_on says) as
/// cloth on `character` (attach_grid_garment; without UVs, on the pattern derive_pattern
/// gives it); a mesh in other units than the character
/// (check_garment_units, against Character::height_m), inside the body, not round it or
/// far from it (check_garment_placement) is refused.
[[nodiscard]] Result<Entity> attach_mesh_garment(Registry& registry, Entity character, const GarmentMeshAsset& mesh,
                                                 const MeshGarmentParams& params, std::string_view name);

/// The one call: the garment mesh `mesh_name` of `file` (its only mesh when empty;
/// import_garment_mesh) as cloth on `character`. Errors name the file or the field.
[[nodiscard]] Result<Entity> attach_garment_file(Registry& registry, Entity character, const std::filesystem::path& file,
                                                 std::string_view mesh_name = {}, const MeshGarmentParams& params = {},
                                                 std::string_view name = "garment");

/// A mesh modelled into a character's own file (a skirt, a dress) as a garment mesh, in its
/// bind pose in the character's model space (units and axes as the character was read; to be
/// placed with GarmentPose::bind): every mesh of `asset` named `mesh_name` (a mesh an
/// exporter split per material is read whole), or, with no name, the one mesh of
/// `modelled` (indices into CharacterAsset::meshes: the modelled garments the body fit left
/// out). No pins are painted; no texture is read. `used` receives the meshes taken. Errors
/// are prefixed with `name` and list the meshes to choose from.
[[nodiscard]] Result<GarmentMeshAsset> garment_mesh_of_character(const CharacterAsset& asset, std::string_view mesh_name,
                                                                 std::span<const std::size_t> modelled, std::string_view name,
                                                                 std::vector<std::size_t>* used = nullptr);

/// `garment`'s cut as a mesh in its character's model space: its particle grid as it was
/// built (Fabric::rest_shape, the shape its rest lengths were measured on, before it was
/// pushed out of the body; the character standing where it stood then), with u = line /
/// lines (a tube's first line written again at u = 1, so that the pattern opens at a seam),
/// v = row / (rows - 1), and its pins painted. Read back and put on the same character in
/// the same pose, it is the same garment.
[[nodiscard]] GarmentMeshAsset garment_as_mesh(Registry& registry, Entity garment);

}  // namespace drape
