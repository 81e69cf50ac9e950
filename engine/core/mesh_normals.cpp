#include "drape/engine/core/mesh_normals.hpp"

#include <cmath>

namespace drape {

void vertex_normals(const Matrix3X& x, std::span<const std::uint32_t> triangles, Matrix3X& normals) {
    normals.setZero(3, x.cols());
    for (std::size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const auto a = triangles[t], b = triangles[t + 1], c = triangles[t + 2];
        const Vec3 face = (x.col(b) - x.col(a)).cross(x.col(c) - x.col(a));
        normals.col(a) += face;
        normals.col(b) += face;
        normals.col(c) += face;
    }
    for (Eigen::Index i = 0; i < normals.cols(); ++i) {
        const Real length = normals.col(i).norm();
        if (length > Real(1e-20) && std::isfinite(length))
            normals.col(i) /= length;
        else
            normals.col(i) = Vec3::UnitY();
    }
}

}  // namespace drape
