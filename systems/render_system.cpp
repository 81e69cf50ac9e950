#include "systems/render_system.hpp"

#include <chrono>
#include <cmath>
#include <limits>

#include "components/character.hpp"
#include "components/ellipsoid_collider.hpp"
#include "components/garment.hpp"
#include "components/skinned_mesh.hpp"

namespace drape {

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
    system.optional_reads = components<Garment, EllipsoidCollider, Character>();
    system.run = [&renderer, first = true](Registry& registry, const FrameContext& context) mutable {
        update_follow_camera(renderer.camera(), registry, first ? 0.0 : context.frame_dt_s);
        first = false;
        renderer.draw_scene(registry);
    };
    return system;
}

Result<std::vector<double>> time_render_frames(Renderer& renderer, Registry& registry, int frames, bool readback) {
    if (frames <= 0) return fail("time_render_frames: frames must be > 0, got " + std::to_string(frames));
    std::vector<double> times_ms;
    times_ms.reserve(static_cast<std::size_t>(frames));
    Image image;
    System system = make_render_system(renderer);
    FrameContext context;
    context.frame_dt_s = 1.0 / 60.0;
    for (int i = 0; i < frames; ++i) {
        const auto start = std::chrono::steady_clock::now();
        context.frame = static_cast<std::uint64_t>(i);
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
