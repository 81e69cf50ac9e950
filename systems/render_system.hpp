// The render system: draws the scene through a Renderer once per frame (phase render).
//
// Reads SkinnedMesh (gates the run); reads Garment, EllipsoidCollider and Character when
// present. Before drawing it moves the camera's target to the first character (the one
// with the lowest entity index) when `Camera::follow` is set. The target comes from the
// skinned vertices themselves, so it follows root motion and in-place clips alike. Then it
// turns the components into the renderer's DrawList (build_draw_list) and draws it; the
// renderer knows nothing of components.
#pragma once

#include <optional>
#include <vector>

#include "drape/engine/core/error.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/engine/core/scheduler.hpp"
#include "drape/engine/render/renderer.hpp"

namespace drape {

/// The render system. The renderer must outlive the scheduler that runs it.
[[nodiscard]] System make_render_system(Renderer& renderer);

/// Fills `list` (cleared first) with the registry's scene, in this order: every
/// SkinnedMesh with vertices (lit, one colour per submesh, a contact shadow), then every
/// Garment with particles and triangles (two-sided cloth in its colour, normals from its
/// particles), and each EllipsoidCollider's world shape when `show_ellipsoids`. Skinned
/// positions that do not match their mesh leave that mesh out, named in `list.problems`.
/// The list points into the components: draw it before they change.
void build_draw_list(Registry& registry, bool show_ellipsoids, DrawList& list);

/// Builds the registry's draw list and draws it: the render system's frame without the
/// camera follow.
void draw_registry(Renderer& renderer, Registry& registry);

/// Where the camera should look for the first character: the centre of its skinned
/// vertices' bounds horizontally, `camera.follow_height_ratio` of its height above its
/// lowest point. Nullopt when the scene has no skinned mesh with vertices.
[[nodiscard]] std::optional<Vec3> follow_target(Registry& registry, const Camera& camera);

/// Moves `camera.target` toward follow_target() with the camera's smoothing time constant
/// over `dt_s` (snaps on the first call, when dt_s <= 0, or when the constant is 0).
void update_follow_camera(Camera& camera, Registry& registry, double dt_s);

/// Renders the registry's current state `frames` times through the render path (skinning
/// system, skin cover system, then the render system: camera follow + draw + resolve);
/// with `readback`, each frame is also read back to the CPU as an export would. Returns
/// the wall time of each frame in ms, in order.
[[nodiscard]] Result<std::vector<double>> time_render_frames(Renderer& renderer, Registry& registry, int frames,
                                                            bool readback = true);

}  // namespace drape
