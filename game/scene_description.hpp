// Scene descriptions: what a world holds, as plain data (docs/scenes.md).
//
// A `SceneDescription` says what a world holds: characters (file, clip, placement,
// playback), garments (type, parameters, colour, model, collision), collider overrides,
// solver settings and a camera. `build_world` (game/world.hpp) turns it into a running
// Registry + Scheduler. Tests and benchmarks build one in code; `drape play --scene` reads
// one from a file (game/scene_file.hpp), which also checks one built in code (validate).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drape/components/garment.hpp"
#include "drape/engine/core/math.hpp"
#include "drape/systems/character/ellipsoid_fit.hpp"
#include "drape/systems/cloth/garment_from_mesh.hpp"

namespace drape {

/// Where a value of a description came from, for error messages. Empty for descriptions
/// built in code.
struct SourceLocation {
    std::string file;   ///< As the user named it.
    int line = 0;       ///< 1-based; 0 = unknown.
    int column = 0;     ///< 1-based, in bytes.

    /// "file:line:column" (or "file", or "" when nothing is known).
    [[nodiscard]] std::string str() const;
    friend bool operator==(const SourceLocation&, const SourceLocation&) = default;
};

/// "where: field: reason", leaving out the empty parts.
[[nodiscard]] std::string located(const SourceLocation& where, std::string_view field, std::string_view reason);

/// A character to load and place.
struct CharacterDescription {
    std::filesystem::path file;          ///< .glb/.gltf/.fbx/...; resolved against the scene folder.
    std::string clip;                    ///< Clip name, or its index as digits; empty: the importer's choice (a walk when there is one).
    Real scale = 1;                      ///< Uniform factor on top of the importer's unit normalisation.
    Vec3 position_m = Vec3::Zero();      ///< World placement of the character's origin.
    Vec3 rotation_deg = Vec3::Zero();    ///< Euler angles, applied as yaw (Y) * pitch (X) * roll (Z).
    double speed = 1;                    ///< Playback rate of the clip.
    bool in_place = true;                ///< true: the walk stays in place; false: root motion moves the character.
    double start_s = 0;                  ///< Clip time at the start (where in its cycle the character begins), s.
    bool hide_modelled_garments = true;  ///< Garments modelled into the file are not drawn while a garment is simulated on the character.
    double thicken_thin_trunk_m = default_thicken_thin_trunk_m;  ///< The body fit's FitOptions::thicken_thin_trunk_m (0: none; docs/cloth.md, "Collision").
    std::filesystem::path motion;        ///< A BVH file whose motion drives the character (retargeted) instead of its clips; empty: none.
    std::vector<std::pair<std::string, std::string>> motion_bones;  ///< Motion joint -> bone, before the built-in matching.
    SourceLocation where;                ///< Of the "file" field, for load errors.

    [[nodiscard]] Quat rotation() const;
    friend bool operator==(const CharacterDescription&, const CharacterDescription&) = default;
};

/// Which builder dresses the character (attach_skirt or attach_dress).
enum class GarmentType : std::uint8_t { skirt, dress };
/// Names as scene files write them: "skirt", "simplified", "lists", ...
[[nodiscard]] const char* garment_type_name(GarmentType t) noexcept;
[[nodiscard]] const char* cloth_model_name(ClothModel m) noexcept;
[[nodiscard]] const char* collision_mode_name(CollisionMode m) noexcept;
[[nodiscard]] const char* cloth_integrator_name(ClothIntegrator i) noexcept;

/// One numeric garment parameter set in a scene: the name of a row of the garment
/// parameter table (systems/cloth/garment_parameters.hpp) or "particles"
/// (game/scene_garment_parameters.hpp).
struct GarmentParameter {
    std::string name;
    double value = 0;
    friend bool operator==(const GarmentParameter&, const GarmentParameter&) = default;
};

/// A garment worn by one of the scene's characters.
struct GarmentDescription {
    GarmentType type = GarmentType::skirt;
    int character = 0;                                   ///< Index into SceneDescription::characters.
    ClothModel model = ClothModel::simplified;
    ClothIntegrator integrator = ClothIntegrator::shipped;  ///< docs/cloth.md "Two integrators".
    WarpSolve warp_solve = WarpSolve::rounds;            ///< docs/cloth.md "Warp lines solved directly".
    PinWeights pin_weights = PinWeights::nearest_vertex; ///< docs/cloth.md "Pins".
    CollisionMode collision = CollisionMode::candidate_lists;
    std::optional<Vec3> color;                           ///< Linear RGB in [0, 1]; none: the garment's default.
    std::string material;                                ///< A material preset (silk, cotton, denim); empty: cotton.
    std::vector<GarmentParameter> parameters;            ///< Overrides of the builder's defaults (after the preset), in file order.
    /// A garment from a file instead of the built-in `type` (docs/garments.md): the mesh,
    /// modelled on the character as it stands when the garment is put on.
    std::filesystem::path file;                          ///< Empty: the built-in `type`.
    std::string mesh;                                    ///< The mesh's name in `file`; empty: its only mesh.
    PinSource pins = PinSource::file;                    ///< Where it is held.
    double spacing_m = 0;                                ///< Between lines and rows; 0: the mesh's own lattice, else 0.029 m.
    GarmentPose modelled_on = GarmentPose::current;      ///< The pose the file's mesh was modelled on.
    SourceLocation where;                                ///< Of the garment object, for build errors.
    friend bool operator==(const GarmentDescription&, const GarmentDescription&) = default;
};

/// Replaces (or adds) the ellipsoid bound to one bone after the colliders were fitted.
struct ColliderOverride {
    int character = 0;
    std::string bone;                                    ///< Bone name as in the character file.
    bool remove = false;                                 ///< Drop the fitted ellipsoid(s) of this bone instead.
    std::optional<Vec3> center_m;                        ///< Bone space.
    std::optional<Vec3> radii_m;
    std::optional<Vec3> rotation_deg;                    ///< Bone space, yaw * pitch * roll.
    std::optional<Real> give_m;                          ///< EllipsoidCollider::give_m.
    SourceLocation where;
    friend bool operator==(const ColliderOverride&, const ColliderOverride&) = default;
};

/// Stepping and robustness settings (see engine/core/scheduler.hpp for the stepping).
struct SolverDescription {
    double fixed_dt_s = 1.0 / 60.0;      ///< Simulated time per fixed step.
    int max_steps_per_frame = 4;         ///< Time beyond this many steps per frame is dropped.
    double time_scale = 1;               ///< Simulated seconds per wall-clock second.
    int substeps = 0;                    ///< Simulation substeps per step; 0 = the cloth's stability rule.
    double max_surface_travel_m = 0.04;  ///< Automatic substeps: how far a collider's surface may move per substep.
    int max_substeps = 8;                ///< Automatic substeps: at most this many per step.
    double max_frame_dt_s = 0.25;        ///< Longer frames (hitches) are clamped to this first.
    double teleport_threshold_m = 1.0;   ///< A body moving further in one step resets its garments.
    int threads = 0;                     ///< Worker threads; 0 = all cores.
    double settle_s = 0.5;               ///< Garments put on settle this long on bodies held in their first pose; 0 = not at all.
    friend bool operator==(const SolverDescription&, const SolverDescription&) = default;
};

/// Camera: an orbit around a target (engine/render/camera.hpp).
struct CameraDescription {
    bool follow = true;                  ///< Keep the target on the first character.
    Vec3 target_m = Vec3(0, 1, 0);       ///< Look-at point (the start point when following).
    Real distance_m = 3.5f;
    Real yaw_deg = 34;                   ///< Around Y; 0 = the camera on +Z of the target.
    Real pitch_deg = 14;                 ///< Above the horizon.
    Real fov_deg = 40;                   ///< Vertical field of view.
    friend bool operator==(const CameraDescription&, const CameraDescription&) = default;
};

/// Everything a world holds (docs/scenes.md).
struct SceneDescription {
    std::string description;             ///< Free text (JSON has no comments).
    std::vector<CharacterDescription> characters;
    std::vector<GarmentDescription> garments;
    std::vector<ColliderOverride> colliders;
    bool ground = true;                  ///< The floor at y = 0 (where it is drawn) is a collider for the garments.
    SolverDescription solver;
    CameraDescription camera;
    friend bool operator==(const SceneDescription&, const SceneDescription&) = default;
};

}  // namespace drape
