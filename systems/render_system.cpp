#include "drape/systems/render_system.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "drape/components/character.hpp"
#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/garment_surface.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/systems/garment_surface_system.hpp"
#include "drape/systems/skin_cover_system.hpp"
#include "drape/systems/skinning_system.hpp"

namespace drape {
namespace {

// Cloth is matte and thin: seen from behind it is lit with the flipped normal.
constexpr SurfaceLook cloth_look{.specular = Real(0.06), .shininess = 12, .rim = Real(0.15), .two_sided = true};

std::uint64_t object_of(Entity e) { return (std::uint64_t(e.index) << 32) | e.generation; }

// Which of an entity's meshes a DrawKey names (an entity could hold a skin and a garment).
enum MeshPart : std::uint32_t { skin_part = 0, garment_part = 1 };

void add_skinned_meshes(Registry& registry, DrawList& list) {
    registry.view<SkinnedMesh>().each([&](Entity e, SkinnedMesh& skin) {
        if (!skin.mesh || skin.positions.cols() == 0) return;
        const MeshAsset& mesh = *skin.mesh;
        const std::string name = "skinned mesh of entity " + std::to_string(e.index);
        if (skin.positions.cols() != Eigen::Index(mesh.vertex_count())) {
            list.problems.push_back(name + ": " + std::to_string(skin.positions.cols()) + " skinned positions for a mesh of " +
                                    std::to_string(mesh.vertex_count()) + " vertices");
            return;
        }
        MeshDraw& draw = list.meshes.emplace_back();
        draw.key = {object_of(e), skin_part};
        draw.name = name;
        draw.positions = &skin.positions;
        draw.normals = skin.normals.cols() == skin.positions.cols() ? &skin.normals : nullptr;
        draw.triangles = mesh.indices;
        for (std::size_t i = 0; i < mesh.submeshes.size(); ++i) {
            if (i < skin.hidden.size() && skin.hidden[i]) continue;
            const Submesh& s = mesh.submeshes[i];
            draw.ranges.push_back({s.first_index, s.index_count, s.color, s.name});
        }
        if (draw.ranges.empty() && !mesh.submeshes.empty()) {  // every part hidden (no ranges would draw them all)
            list.meshes.pop_back();
            return;
        }
        draw.contact_shadow = true;
    });
}

void add_garments(Registry& registry, DrawList& list) {
    registry.view<Garment>().each([&](Entity e, Garment& garment) {
        if (!garment.fabric || garment.state.x.cols() == 0 || garment.fabric->triangles.empty()) return;
        MeshDraw& draw = list.meshes.emplace_back();
        draw.key = {object_of(e), garment_part};
        draw.name = "garment of entity " + std::to_string(e.index);
        draw.positions = &garment.state.x;
        draw.normals = nullptr;  // from the particles, every frame
        draw.triangles = garment.fabric->triangles;
        // Drawn as authored: the artist's mesh where the garment surface system placed it.
        if (const auto* surface = registry.try_get<GarmentSurface>(e);
            surface && !surface->triangles.empty() && surface->positions.cols() == static_cast<Eigen::Index>(surface->carriers.size())) {
            draw.positions = &surface->positions;
            draw.normals = &surface->normals;
            draw.triangles = surface->triangles;
            if (surface->base_color && surface->uvs.cols() == surface->positions.cols()) {
                draw.texture = surface->base_color.get();
                draw.uvs = &surface->uvs;
            }
        }
        draw.color = draw.texture != nullptr ? Vec3::Ones() : garment.config.color;
        draw.look = cloth_look;
    });
}

}  // namespace

void build_draw_list(Registry& registry, bool show_ellipsoids, DrawList& list) {
    list.clear();
    add_skinned_meshes(registry, list);
    add_garments(registry, list);
    if (show_ellipsoids)
        registry.view<EllipsoidCollider>().each([&](Entity, EllipsoidCollider& c) { list.ellipsoids.push_back(c.world); });
}

void draw_registry(Renderer& renderer, Registry& registry) {
    DrawList list;
    build_draw_list(registry, renderer.show_ellipsoids(), list);
    renderer.draw(list);
}

std::optional<Vec3> follow_target(Registry& registry, const Camera& camera) {
    // The first character: lowest entity index among skinned meshes that are characters,
    // or among all skinned meshes when none is.
    const SkinnedMesh* chosen = nullptr;
    bool chosen_is_character = false;
    std::uint32_t chosen_index = std::numeric_limits<std::uint32_t>::max();
    registry.view<SkinnedMesh>().each([&](Entity e, SkinnedMesh& skin) {
        if (skin.positions.cols() == 0) return;
        const bool is_character = registry.has<Character>(e);
        if (chosen != nullptr && chosen_is_character && !is_character) return;
        if (chosen != nullptr && chosen_is_character == is_character && e.index > chosen_index) return;
        chosen = &skin;
        chosen_is_character = is_character;
        chosen_index = e.index;
    });
    if (chosen == nullptr) return std::nullopt;
    const auto bounds = finite_bounds(chosen->positions);
    if (!bounds) return std::nullopt;
    const Vec3& lo = bounds->lo;
    const Vec3& hi = bounds->hi;
    return Vec3(Real(0.5) * (lo.x() + hi.x()), lo.y() + camera.follow_height_ratio * (hi.y() - lo.y()),
                Real(0.5) * (lo.z() + hi.z()));
}

void update_follow_camera(Camera& camera, Registry& registry, double dt_s) {
    if (!camera.follow) return;
    const auto target = follow_target(registry, camera);
    if (!target) return;
    const double tau = camera.follow_time_constant_s;
    if (dt_s <= 0 || tau <= 0 || !camera.target.allFinite()) {
        camera.target = *target;
        return;
    }
    const Real blend = Real(1 - std::exp(-dt_s / tau));
    camera.target += blend * (*target - camera.target);
}

System make_render_system(Renderer& renderer) {
    System system;
    system.name = "render";
    system.phase = Phase::render;
    system.reads = components<SkinnedMesh>();
    system.optional_reads = components<Garment, GarmentSurface, EllipsoidCollider, Character>();
    // The list lives with the system, so its buffers are reused from frame to frame.
    system.run = [&renderer, first = true, list = DrawList{}](Registry& registry, const FrameContext& context) mutable {
        update_follow_camera(renderer.camera(), registry, first ? 0.0 : context.frame_dt_s);
        first = false;
        build_draw_list(registry, renderer.show_ellipsoids(), list);
        renderer.draw(list);
    };
    return system;
}

Result<std::vector<double>> time_render_frames(Renderer& renderer, Registry& registry, int frames, bool readback) {
    if (frames <= 0) return fail("time_render_frames: frames must be > 0, got " + std::to_string(frames));
    std::vector<double> times_ms;
    times_ms.reserve(static_cast<std::size_t>(frames));
    Image image;
    System skinning = make_skinning_system();
    System cover = make_skin_cover_system();
    System surfaces = make_garment_surface_system();
    System system = make_render_system(renderer);
    FrameContext context;
    context.frame_dt_s = 1.0 / 60.0;
    for (int i = 0; i < frames; ++i) {
        const auto start = std::chrono::steady_clock::now();
        context.frame = static_cast<std::uint64_t>(i);
        skinning.run(registry, context);
        cover.run(registry, context);
        surfaces.run(registry, context);
        system.run(registry, context);
        if (readback) {
            if (auto ok = renderer.read_pixels(image); !ok) return fail(ok.error().message);
        } else {
            renderer.finish();
        }
        const auto end = std::chrono::steady_clock::now();
        times_ms.push_back(std::chrono::duration<double, std::milli>(end - start).count());
    }
    return times_ms;
}

}  // namespace drape
