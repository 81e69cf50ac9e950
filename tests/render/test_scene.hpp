// Small scenes built from simple meshes, so render tests do not depend on the importer.
#pragma once

#include <cmath>
#include <memory>
#include <numbers>

#include "drape/components/character.hpp"
#include "drape/components/ellipsoid_collider.hpp"
#include "drape/components/garment.hpp"
#include "drape/components/skinned_mesh.hpp"
#include "drape/engine/core/registry.hpp"

namespace drape::test {

/// A closed cylinder standing on the ground at (x, z): radius_m, height_m, one submesh.
inline SkinnedMesh make_cylinder_body(Real x, Real z, Real radius_m, Real height_m, const Vec3& color) {
    constexpr int segments = 32, stacks = 8;
    auto mesh = std::make_shared<MeshAsset>();
    const int ring = segments + 1;
    const int side = ring * (stacks + 1);
    mesh->bind_positions.resize(3, side + 2);
    mesh->bind_normals.resize(3, side + 2);
    for (int i = 0; i <= stacks; ++i)
        for (int j = 0; j <= segments; ++j) {
            const Real phi = 2 * Real(std::numbers::pi) * Real(j) / segments;
            const Vec3 n(std::cos(phi), 0, std::sin(phi));
            mesh->bind_positions.col(i * ring + j) = Vec3(x, height_m * Real(i) / stacks, z) + radius_m * n;
            mesh->bind_normals.col(i * ring + j) = n;
        }
    const auto bottom = std::uint32_t(side), top = std::uint32_t(side + 1);
    mesh->bind_positions.col(bottom) = Vec3(x, 0, z);
    mesh->bind_normals.col(bottom) = -Vec3::UnitY();
    mesh->bind_positions.col(top) = Vec3(x, height_m, z);
    mesh->bind_normals.col(top) = Vec3::UnitY();
    for (int i = 0; i < stacks; ++i)
        for (int j = 0; j < segments; ++j) {
            const auto a = std::uint32_t(i * ring + j), b = a + 1, c = a + std::uint32_t(ring), d = c + 1;
            mesh->indices.insert(mesh->indices.end(), {a, c, b, b, c, d});  // outward, counter-clockwise
        }
    for (int j = 0; j < segments; ++j) {
        const auto a = std::uint32_t(j), b = a + 1;
        const auto ta = std::uint32_t(stacks * ring + j), tb = ta + 1;
        mesh->indices.insert(mesh->indices.end(), {bottom, a, b, top, tb, ta});
    }
    const auto count = mesh->bind_positions.cols();
    mesh->bone_indices.setZero(4, count);
    mesh->bone_weights.setZero(4, count);
    mesh->bone_weights.row(0).setOnes();
    mesh->submeshes.push_back({"body", 0, std::uint32_t(mesh->indices.size()), color});
    SkinnedMesh skin;
    skin.positions = mesh->bind_positions;
    skin.normals = mesh->bind_normals;
    skin.mesh = std::move(mesh);
    return skin;
}

/// A vertical square cloth panel of n x n particles in the plane z = z_m, lower-left corner
/// at (x_m, y_m), facing +Z (counter-clockwise seen from +Z).
inline Garment make_panel(Real x_m, Real y_m, Real z_m, Real size_m, int n, const Vec3& color) {
    auto topology = std::make_shared<Fabric>();
    Garment garment;
    garment.state.x.resize(3, n * n);
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            garment.state.x.col(i * n + j) = Vec3(x_m + size_m * Real(j) / Real(n - 1), y_m + size_m * Real(i) / Real(n - 1), z_m);
    for (int i = 0; i + 1 < n; ++i)
        for (int j = 0; j + 1 < n; ++j) {
            const auto a = std::uint32_t(i * n + j), b = a + 1, c = a + std::uint32_t(n), d = c + 1;
            topology->triangles.insert(topology->triangles.end(), {a, b, c, b, d, c});
        }
    garment.fabric = std::move(topology);
    garment.state.v.setZero(3, n * n);
    garment.state.inv_mass.setOnes(n * n);
    garment.config.color = color;
    return garment;
}

}  // namespace drape::test
