#include "drape/engine/render/camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace drape {

std::optional<Bounds> finite_bounds(const Matrix3X& points) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<Real>::infinity()), hi = -lo;
    bool any = false;
    for (Eigen::Index i = 0; i < points.cols(); ++i) {
        const Vec3 p = points.col(i);
        if (!p.allFinite()) continue;
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
        any = true;
    }
    if (!any) return std::nullopt;
    return Bounds{lo, hi};
}

Vec3 Camera::eye() const {
    const Real cp = std::cos(pitch_rad);
    const Vec3 offset(std::sin(yaw_rad) * cp, std::sin(pitch_rad), std::cos(yaw_rad) * cp);
    return target + distance_m * offset;
}

Mat4 Camera::view() const {
    const Vec3 e = eye();
    const Vec3 f = (target - e).normalized();
    Vec3 s = f.cross(Vec3::UnitY());
    if (s.squaredNorm() < Real(1e-12)) s = Vec3::UnitX();  // looking straight down or up
    s.normalize();
    const Vec3 u = s.cross(f);
    Mat4 m = Mat4::Identity();
    m.block<1, 3>(0, 0) = s.transpose();
    m.block<1, 3>(1, 0) = u.transpose();
    m.block<1, 3>(2, 0) = -f.transpose();
    m(0, 3) = -s.dot(e);
    m(1, 3) = -u.dot(e);
    m(2, 3) = f.dot(e);
    return m;
}

Mat4 Camera::projection(Real aspect) const {
    const Real t = Real(1) / std::tan(fov_y_rad / 2);
    Mat4 m = Mat4::Zero();
    m(0, 0) = t / aspect;
    m(1, 1) = t;
    m(2, 2) = (far_m + near_m) / (near_m - far_m);
    m(2, 3) = 2 * far_m * near_m / (near_m - far_m);
    m(3, 2) = -1;
    return m;
}

std::optional<ScreenPoint> Camera::project(const Vec3& world, int width, int height) const {
    if (width <= 0 || height <= 0) return std::nullopt;
    const Vec4 clip = projection(Real(width) / Real(height)) * view() * world.homogeneous();
    if (clip.w() <= Real(0)) return std::nullopt;
    const Vec3 ndc = clip.head<3>() / clip.w();
    return ScreenPoint{(ndc.x() * Real(0.5) + Real(0.5)) * Real(width),
                       (Real(0.5) - ndc.y() * Real(0.5)) * Real(height), ndc.z()};
}

void Camera::orbit(Real dx_px, Real dy_px) {
    constexpr Real radians_per_px = Real(0.008);
    constexpr Real pitch_limit = Real(1.45);
    yaw_rad -= dx_px * radians_per_px;
    pitch_rad = std::clamp(pitch_rad + dy_px * radians_per_px, -pitch_limit, pitch_limit);
}

void Camera::zoom(Real steps) {
    distance_m = std::clamp(distance_m * std::pow(Real(0.9), steps), Real(0.3), Real(50));
}

}  // namespace drape
