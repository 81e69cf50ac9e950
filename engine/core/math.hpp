// Drape's numeric types. One alias decides the precision of every simulated quantity.
//
// Particles and colliders use `Real` (float): an 837-particle skirt fits in L1 cache, Eigen
// vectorises four lanes, and the explicit scheme's own error (method §3.4) dwarfs float's
// rounding. Poses and the scheduler's clock use double where accumulated time matters.
#pragma once

// GCC 12 warns inside its own AVX-512 intrinsics, which Eigen uses for 16-float vectors
// (-Wmaybe-uninitialized, or -Wuninitialized with the sanitizers, on the intrinsics'
// placeholder operand: GCC bug 105593, fixed in 13).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#include <Eigen/Core>
#include <Eigen/Geometry>
#pragma GCC diagnostic pop

namespace drape {

using Real = float;  ///< Precision of particles, springs and colliders.

using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Vec4 = Eigen::Matrix<Real, 4, 1>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;
using Mat4 = Eigen::Matrix<Real, 4, 4>;
using Quat = Eigen::Quaternion<Real>;
using Affine3 = Eigen::Transform<Real, 3, Eigen::Affine>;
using Matrix3X = Eigen::Matrix<Real, 3, Eigen::Dynamic>;  ///< One column per point (x, y, z adjacent).
/// One contiguous row per coordinate (structure of arrays): whole-row vector arithmetic.
using Matrix3XRows = Eigen::Matrix<Real, 3, Eigen::Dynamic, Eigen::RowMajor>;
using Matrix4X = Eigen::Matrix<Real, 4, Eigen::Dynamic>;
using Matrix2X = Eigen::Matrix<Real, 2, Eigen::Dynamic>;
using VectorX = Eigen::Matrix<Real, Eigen::Dynamic, 1>;
using Vec4i = Eigen::Matrix<int, 4, 1>;

/// Standard gravity, m/s^2, along -Y (Drape is Y up, metres, seconds).
inline constexpr Real standard_gravity_m_s2 = Real(9.80665);

}  // namespace drape
