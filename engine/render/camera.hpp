// An orbit camera: it looks at a target from a yaw, a pitch and a distance.
//
// Y up, right-handed, OpenGL clip conventions (depth -1..1). Yaw 0 looks along -Z
// (the camera sits on +Z of the target); positive yaw turns the camera to the +X side.
// The render system moves `target` to follow the first character when `follow` is set.
#pragma once

#include <optional>

#include "drape/engine/core/math.hpp"

namespace drape {

/// A pixel position: x right, y down from the top-left corner (as in `Image`).
struct ScreenPoint {
    float x_px = 0;
    float y_px = 0;
    float depth = 0;  ///< Normalised device depth, -1 (near) .. 1 (far).
};

/// Axis-aligned bounds of the finite points of a point set (non-finite points are
/// skipped, so one NaN vertex cannot move the camera or a shadow); nullopt when none is.
struct Bounds {
    Vec3 lo;
    Vec3 hi;
};
[[nodiscard]] std::optional<Bounds> finite_bounds(const Matrix3X& points);

struct Camera {
    Vec3 target = Vec3(0, 1, 0);   ///< m, the point looked at.
    Real yaw_rad = Real(0.6);
    Real pitch_rad = Real(0.25);   ///< Above the horizon when positive.
    Real distance_m = Real(3.5);
    Real fov_y_rad = Real(0.7);
    Real near_m = Real(0.05);
    Real far_m = Real(100);

    bool follow = true;                 ///< The render system keeps `target` on the first character.
    Real follow_height_ratio = Real(0.55);  ///< Target height over the character's feet, as a share of its height.
    Real follow_time_constant_s = Real(0.3);///< Smoothing of the followed target (0 = rigid).

    [[nodiscard]] Vec3 eye() const;
    [[nodiscard]] Mat4 view() const;
    [[nodiscard]] Mat4 projection(Real aspect) const;
    /// Where a world point lands in a width x height image; nullopt behind the camera.
    [[nodiscard]] std::optional<ScreenPoint> project(const Vec3& world, int width, int height) const;

    /// Mouse orbit: pixels of drag to angles (pitch clamped away from the poles).
    void orbit(Real dx_px, Real dy_px);
    /// Wheel zoom: each step moves 10 % closer (negative: farther), distance kept in [0.3, 50] m.
    void zoom(Real steps);
};

}  // namespace drape
