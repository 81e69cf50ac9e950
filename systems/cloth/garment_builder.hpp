// Garment builders: a skirt and a dress placed around a character from its ellipsoid
// colliders, and a flat rectangle for tests (method §3.2 grid, §3.5 fitting zones).
//
// Placement (skirt and dress): the character's colliders are the EllipsoidCollider
// entities whose `character` is that entity, in entity order, and must have been placed
// (spawn_character places them, the collider system keeps them placed, or a test set
// `world` and `initialised`). On a character
// with BodyLandmarks (systems/character/body_landmarks.hpp) the ring sits at its waist
// (skirt) or 2 % of its height under the armpits (dress), on the vertical axis through
// that landmark as the character stands now; elsewhere the body's height is the vertical
// extent of its colliders, the axis runs through the mean of their centres and the ring
// sits at a fixed share of the height. At the ring height the outline of the colliders that cross that height and lie near the axis (not
// arms or hands) is sampled along each warp line's direction; the garment is a truncated
// cone from that outline (plus ease), flaring outward, and is then pushed out of every
// collider. The top `fitting_rows` rows are pinned (method §3.5):
//   - skinned to the skin when the character has a Skeleton with skinning matrices
//     (weights of the nearest skin vertex, or with PinWeights::skin_surface the trunk
//     skin's where the pin sits, when it has a SkinnedMesh, else its collider's bone), so
//     the pins follow linear blend skinning like the body mesh;
//   - otherwise bound rigidly to the nearest collider (analytic bodies).
// Parameter errors name the field ("skirt.length_m: must be in (0, 10] m, got -1"); the
// ranges are those of the garment parameter table (systems/cloth/garment_parameters.hpp).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "drape/components/garment.hpp"
#include "drape/engine/core/error.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/character/ellipsoid_fit.hpp"

namespace drape {

/// Where a tube's ring sits on a body with landmarks (components/body_landmarks.hpp).
enum class RingPlace : std::uint8_t {
    waist,       ///< BodyLandmarks::waist: a skirt.
    under_arms,  ///< Just under where the arms' skin meets the trunk (BodyLandmarks::arms_meet_trunk): a strapless dress.
};

/// Ring height / body height on a body without landmarks (a non-humanoid, an analytic body).
[[nodiscard]] Real fallback_ring_height_fraction(RingPlace place) noexcept;

/// Whose weights a skinned pin takes when it is bound (docs/cloth.md "Pins").
enum class PinWeights : std::uint8_t {
    nearest_vertex,  ///< The nearest skin vertex's, on the trunk.
    skin_surface,    ///< The trunk skin's where the pin sits: its face's vertices blended
                     ///< (systems/character/trunk_skin.hpp); neighbouring pins move together.
};

/// A skirt or a dress: a tube hung from a ring around the body, flaring into a truncated
/// cone (see the placement rules above). A skirt and a dress differ only in their values:
/// the ring is the waist for a skirt and under the arms for a dress. The defaults are the skirt's (`skirt()`); `dress()` gives the dress's. Ranges,
/// units and meanings of the numeric fields: the garment parameter table
/// (systems/cloth/garment_parameters.hpp), which validate(TubeParams) walks.
struct TubeParams {
    int warp_lines = 27;              ///< Lines around the body (n); a multiple of weft_stride.
    int particles_per_line = 31;      ///< Particles down each line (m). 27 x 31 = 837.
    int weft_stride = 3;              ///< Every weft_stride-th line is layer 1 (method §3.2).
    Real line_spacing_m = Real(0.029); ///< > 0: more lines on a wider body, at most this far apart round the ring (never fewer than warp_lines); 0: warp_lines.
    Real hem_spacing_leg_widths = 2;  ///< > 0: more lines where the hem's layer-1 lines would stand farther apart than this x the thinner leg's width at the hem's height; 0: no limit.
    Real length_m = Real(0.55);       ///< Along the cone from the ring to the hem.
    Real hem_clearance_fraction = Real(0.09);  ///< The hem stays at least this x body height above the body's lowest point (the ankles): on a shorter body the garment is shortened (0: no limit).
    Real flare_deg = Real(18);        ///< Cone half-angle from vertical.
    Real ease_m = Real(0.01);         ///< Gap between the body outline at the ring and the cloth.
    RingPlace ring_at = RingPlace::waist;  ///< Where the ring sits on a character with BodyLandmarks.
    Real ring_height_fraction = 0;    ///< > 0: ring height / body height instead (used when ring_height_m is 0).
    Real ring_height_m = 0;           ///< > 0: ring height above the body's lowest point.
    Real torso_radius_fraction = Real(0.12);  ///< Colliders centred farther than this x height from the axis (arms) are not outline.
    int fitting_rows = 1;             ///< Rows pinned to the body (method §3.5).
    Real inertia_linear = InertiaScales{}.linear;                    ///< InertiaScales::linear of the garment (1: physical).
    Real inertia_angular = InertiaScales{}.angular;                  ///< InertiaScales::angular.
    Real inertia_max_linear_m_s2 = InertiaScales{}.max_linear_m_s2;  ///< InertiaScales::max_linear_m_s2 (0: no bound).
    Real inertia_max_fall_m_s2 = InertiaScales{}.max_fall_m_s2;      ///< InertiaScales::max_fall_m_s2: free fall (0: no bound).
    Real max_distance_share = 0;      ///< GarmentConfig::max_distance_share (0: none).
    int max_distance_on_skin = 0;     ///< 1: GarmentConfig::max_distance_on_skin (the spheres follow the skin of trunk and legs).
    /// > 0: no collision with the torso's and pelvis's ellipsoids whose smallest radius is at most this (the
    /// anchor's apart): by default the pieces the body fit leaves that thin (FitOptions::thicken_thin_trunk_m);
    /// 0: with every ellipsoid (docs/cloth.md "Thin trunk pieces").
    Real thin_trunk_piece_m = Real(default_thicken_thin_trunk_m);
    PinWeights pin_weights = PinWeights::nearest_vertex;  ///< How the skinned pins are bound.
    ClothMaterial material{};
    ClothModel model = ClothModel::simplified;
    ClothIntegrator integrator = ClothIntegrator::shipped;
    CollisionMode collision = CollisionMode::candidate_lists;
    Vec3 color = Vec3(0.75f, 0.12f, 0.18f);

    /// The paper's skirt: 27 x 31 = 837 particles hung from the waist.
    [[nodiscard]] static TubeParams skirt() { return {}; }
    /// A strapless dress hung from the chest under the arms: 120 x 84 = 10,080 particles, the
    /// same cloth.
    [[nodiscard]] static TubeParams dress() {
        TubeParams p;
        p.warp_lines = 120;
        p.particles_per_line = 84;
        p.length_m = Real(1.05);
        p.flare_deg = Real(10);
        p.ease_m = Real(0.015);
        p.ring_at = RingPlace::under_arms;  // the arms stay outside the dress
        p.fitting_rows = 2;
        p.color = Vec3(0.15f, 0.3f, 0.7f);
        return p;
    }
};

/// The configuration a garment built from `params` runs with (its model, integrator,
/// collision, material, inertia, max distance and colour).
[[nodiscard]] GarmentConfig garment_config(const TubeParams& params);

/// A flat rectangle (tests, demos): lines along +X, rows down -Y (hanging) or along +Z (lying).
struct RectangleParams {
    int warp_lines = 16;              ///< (warp_lines - 1) must be a multiple of weft_stride.
    int particles_per_line = 16;
    int weft_stride = 3;
    Real width_m = 1;                 ///< Across the lines.
    Real length_m = 1;                ///< Down each line.
    Vec3 origin = Vec3(0, 2, 0);      ///< Position of line 0, row 0.
    bool hanging = true;              ///< true: rows go down -Y; false: rows go along +Z (horizontal sheet).
    bool pin_top_row = true;          ///< Pin row 0 in world space.
    ClothMaterial material{};
    ClothModel model = ClothModel::simplified;
    ClothIntegrator integrator = ClothIntegrator::shipped;
    CollisionMode collision = CollisionMode::candidate_lists;
    Vec3 color = Vec3(0.8f, 0.8f, 0.8f);
};

/// Most particles one garment may have (warp_lines x particles_per_line), for every
/// builder and so for scene files too. The 10,080-particle dress is the large case Drape is
/// made for; this leaves 25 times that, while refusing counts that would take seconds per
/// frame (1,000,000 particles: 2.6 s per frame on one core).
inline constexpr int max_garment_particles = 250'000;

/// Checks parameters; the error names the field, prefixed with `garment` ("skirt",
/// "dress"): "skirt.length_m: must be in (0, 10] m, got -1".
[[nodiscard]] Result<void> validate(const TubeParams& params, std::string_view garment);
[[nodiscard]] Result<void> validate(const RectangleParams& params);
[[nodiscard]] Result<void> validate(const ClothMaterial& material, std::string_view prefix);

/// Cooks a grid topology from rest positions in grid order (column line * m + row).
[[nodiscard]] Result<std::shared_ptr<const Fabric>> build_grid_topology(
    int warp_lines, int particles_per_line, int weft_stride, bool closed, const Matrix3X& grid_positions,
    std::string_view prefix);

/// Skirt on `character` (see the placement rules above): a tube whose errors are named
/// "skirt.<field>". Returns the garment entity.
[[nodiscard]] Result<Entity> attach_skirt(Registry& registry, Entity character, const TubeParams& params = TubeParams::skirt());

/// Dress on `character`: a tube whose errors are named "dress.<field>". Returns the garment entity.
[[nodiscard]] Result<Entity> attach_dress(Registry& registry, Entity character, const TubeParams& params = TubeParams::dress());

/// A garment from any particle grid (garments from files: systems/cloth/garment_from_mesh.hpp),
/// laid out as the built-in ones are (components/garment.hpp): `warp_lines` lines of
/// `particles_per_line`, row 0 at the held edge.
struct GridGarment {
    int warp_lines = 0;
    int particles_per_line = 0;
    int weft_stride = 3;               ///< Closed: warp_lines a multiple of it; open: warp_lines - 1.
    bool closed = false;               ///< The last line's weft joins the first (a tube).
    Matrix3X grid_positions;           ///< Character model space, grid order (line * m + row).
    std::vector<std::uint8_t> pinned;  ///< Grid order: 1 = held to the skin (method §3.5).
    GarmentConfig config;              ///< Model, integrator, collision, material, inertia, colour.
    PinWeights pin_weights = PinWeights::nearest_vertex;  ///< How the skinned pins are bound.
};

/// `grid` on `character`, placed by the character's Transform; pins bound to the skin as the
/// built-in garments' are; it collides with every collider of the character, except the
/// upper arms when it is held between the midpoint of the waist and the armpits and that of
/// the armpits and the shoulders (they hang outside a strapless dress; a cape held on the
/// shoulders lies over them). Errors are named `name` ("garments[0]").
[[nodiscard]] Result<Entity> attach_grid_garment(Registry& registry, Entity character, const GridGarment& grid,
                                                 std::string_view name);

/// A flat rectangle, pinned in world space, colliding with `colliders` (no body).
[[nodiscard]] Result<Garment> make_rectangle(const RectangleParams& params, std::span<const Entity> colliders = {});
[[nodiscard]] Result<Entity> attach_rectangle(Registry& registry, const RectangleParams& params,
                                              std::span<const Entity> colliders = {});

/// The character's colliders, in entity order (what a garment on it collides with).
[[nodiscard]] std::vector<Entity> character_colliders(Registry& registry, Entity character);

/// Back to rest around the body at its current place (see reset_garment_state). Does
/// nothing for an entity without a Garment.
void reset_garment(Registry& registry, Entity garment);

}  // namespace drape
