// Collider frames for the cloth (method §2, §5); see body.hpp for conventions.
#include "drape/systems/cloth/body.hpp"

#include <bit>
#include <cstdint>

#include "drape/systems/cloth/collision.hpp"

namespace drape {

EllipsoidFrame make_ellipsoid_frame(const Affine3& unit_to_world) {
    EllipsoidFrame f;
    const Mat3 linear = unit_to_world.linear();
    for (int i = 0; i < 3; ++i) {
        const Real r = linear.col(i).norm();
        f.radii_m[i] = r;
        f.rotation.col(i) = r > 0 ? Vec3(linear.col(i) / r) : Vec3::Unit(i);
    }
    f.center = unit_to_world.translation();
    f.to_unit = f.radii_m.cwiseInverse().asDiagonal() * f.rotation.transpose();
    f.active = (f.radii_m.array() > 0).all() && f.to_unit.allFinite() && f.center.allFinite();
    return f;
}

Affine3 unit_to_world(const EllipsoidFrame& frame) {
    Affine3 t = Affine3::Identity();
    t.linear() = frame.rotation * frame.radii_m.asDiagonal();
    t.translation() = frame.center;
    return t;
}

EllipsoidFrame interpolate_collider(const EllipsoidCollider& collider, Real alpha) {
    EllipsoidFrame frame;
    if (!collider.initialised || alpha >= 1) {
        frame = make_ellipsoid_frame(collider.world);
    } else {
        const EllipsoidFrame a = make_ellipsoid_frame(collider.previous_world);
        const EllipsoidFrame b = make_ellipsoid_frame(collider.world);
        Affine3 t = Affine3::Identity();
        const Quat q = Quat(a.rotation).slerp(alpha, Quat(b.rotation));
        t.linear() = q.toRotationMatrix() * ((1 - alpha) * a.radii_m + alpha * b.radii_m).asDiagonal();
        t.translation() = (1 - alpha) * a.center + alpha * b.center;
        frame = make_ellipsoid_frame(t);
    }
    frame.velocity_m_s = collider.velocity_m_s;
    frame.acceleration_m_s2 = collider.acceleration_m_s2;
    frame.angular_velocity_rad_s = collider.angular_velocity_rad_s;
    // In world units: scaled as the radii are (a character's Transform may carry a scale).
    if (collider.give_m > 0 && collider.radii_m.sum() > 0) frame.give_m = collider.give_m * frame.radii_m.sum() / collider.radii_m.sum();
    return frame;
}

void update_frames(const Registry& registry, const GarmentBody& body, std::vector<EllipsoidFrame>& frames, Real alpha) {
    frames.resize(body.colliders.size());
    for (std::size_t i = 0; i < body.colliders.size(); ++i) {
        const EllipsoidCollider* c = registry.try_get<EllipsoidCollider>(body.colliders[i]);
        if (c == nullptr) {
            frames[i].active = false;
            continue;
        }
        frames[i] = interpolate_collider(*c, alpha);
    }
}

Affine3 anchor_frame(std::span<const EllipsoidFrame> frames, std::int32_t anchor) {
    Affine3 t = Affine3::Identity();
    if (anchor < 0 || static_cast<std::size_t>(anchor) >= frames.size()) return t;
    const EllipsoidFrame& f = frames[static_cast<std::size_t>(anchor)];
    if (!f.active) return t;
    t.linear() = f.rotation;
    t.translation() = f.center;
    return t;
}

// Arms and hands hang outside a garment. A rest shape placed round the trunk can put cloth
// inside a forearm or a hand hanging at the side; pushed out the shortest way, cloth on the
// limb's far side from the body wrapped round the outside of it, the limb inside the
// garment, and tore as it swung (Male_Casual's dress started at four points of his walk:
// 74-280 %). Cloth on the near side is left to the collision, whose shortest way already
// leads in (moved in too, Female_Alternative's dress, whose hands hang against her hips,
// kept the contract from 3 of 8 starts instead of 7).
void tuck_under_limbs(const Registry& registry, const GarmentBody& body, std::span<const EllipsoidFrame> frames, Matrix3X& x,
                      const VectorX& inv_mass) {
    if (body.anchor < 0 || static_cast<std::size_t>(body.anchor) >= frames.size()) return;
    std::uint64_t arms = 0;
    for (std::size_t e = 0; e < body.colliders.size() && e < frames.size() && e < 64; ++e) {
        const auto* c = registry.try_get<EllipsoidCollider>(body.colliders[e]);
        if (c && frames[e].active && is_arm(c->region)) arms |= std::uint64_t(1) << e;
    }
    if (arms == 0) return;
    const Vec3 centre = frames[static_cast<std::size_t>(body.anchor)].center;
    const auto level = [](Vec3 v) {
        v.y() = 0;
        return v;
    };
    for (Eigen::Index p = 0; p < x.cols(); ++p) {
        if (inv_mass[p] == 0) continue;
        const Vec3 at = x.col(p);
        bool far_side = false;
        for (std::uint64_t bits = arms; bits != 0 && !far_side; bits &= bits - 1) {
            const EllipsoidFrame& f = frames[static_cast<std::size_t>(std::countr_zero(bits))];
            far_side = to_unit_sphere(f, at).squaredNorm() < 1 && level(at - centre).norm() >= level(f.center - centre).norm();
        }
        const Vec3 in = level(centre - at);
        if (!far_side || in.norm() < Real(1e-6)) continue;
        const Vec3 d = in.normalized();
        x.col(p) = at + first_point_outside(frames, arms, at, d) * d;
    }
}

}  // namespace drape
