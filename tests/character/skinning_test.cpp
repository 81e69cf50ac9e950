// Linear blend skinning (method §1.2).
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

#include "drape/systems/character/pose.hpp"

namespace drape {
namespace {

// Largest coordinate difference, column by column (GCC 12 warns falsely on Eigen's AVX-512
// max over a whole dynamic matrix). Unequal sizes count as infinitely far apart.
Real max_difference(const Matrix3X& a, const Matrix3X& b) {
    if (a.cols() != b.cols()) return std::numeric_limits<Real>::infinity();
    Real worst = 0;
    for (Eigen::Index j = 0; j < a.cols(); ++j) worst = std::max(worst, (a.col(j) - b.col(j)).cwiseAbs().maxCoeff());
    return worst;
}

MeshAsset random_mesh(Eigen::Index n, int bones, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<Real> u(-1, 1);
    MeshAsset m;
    m.bind_positions.resize(3, n);
    m.bind_normals.resize(3, n);
    m.bone_indices.resize(4, n);
    m.bone_weights.resize(4, n);
    for (Eigen::Index j = 0; j < n; ++j) {
        m.bind_positions.col(j) = Vec3(u(rng), u(rng), u(rng));
        m.bind_normals.col(j) = Vec3(u(rng), u(rng), u(rng)).normalized();
        Vec4 w(std::abs(u(rng)), std::abs(u(rng)), std::abs(u(rng)), std::abs(u(rng)));
        m.bone_weights.col(j) = w / w.sum();
        for (int k = 0; k < 4; ++k) m.bone_indices(k, j) = int(rng() % unsigned(bones));
    }
    return m;
}

std::vector<Affine3> random_transforms(int bones, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<Real> u(-1, 1);
    std::vector<Affine3> out;
    for (int b = 0; b < bones; ++b) {
        Affine3 a = Affine3::Identity();
        a.translate(Vec3(u(rng), u(rng), u(rng)));
        a.rotate(Quat(u(rng), u(rng), u(rng), u(rng)).normalized());
        out.push_back(a);
    }
    return out;
}

TEST(Skinning, IdentityMatricesGiveTheBindMeshExactly) {
    const MeshAsset m = random_mesh(100, 5, 1);
    std::vector<Affine3> identity(5, Affine3::Identity());
    Matrix3X p, n;
    skin_mesh(m, identity, Affine3::Identity(), p, n);
    EXPECT_LE(max_difference(p, m.bind_positions), 1e-6f);  // weights sum to 1 within rounding
    EXPECT_LE(max_difference(n, m.bind_normals), 1e-6f);
}

TEST(Skinning, OneRigidMotionForEveryBoneMovesTheMeshRigidly) {
    const MeshAsset m = random_mesh(500, 4, 2);
    const Affine3 motion = random_transforms(1, 3)[0];
    std::vector<Affine3> same(4, motion);
    Matrix3X p, n;
    skin_mesh(m, same, Affine3::Identity(), p, n);
    EXPECT_LE(max_difference(p, motion * m.bind_positions), 1e-5f);
    EXPECT_LE(max_difference(n, motion.linear() * m.bind_normals), 1e-5f);
}

TEST(Skinning, WorldTransformIsAppliedAfterTheBlend) {
    const MeshAsset m = random_mesh(300, 6, 4);
    const auto bones = random_transforms(6, 5);
    const Affine3 world = random_transforms(1, 6)[0];
    Matrix3X model, model_n, in_world, in_world_n;
    skin_mesh(m, bones, Affine3::Identity(), model, model_n);
    skin_mesh(m, bones, world, in_world, in_world_n);
    EXPECT_LE(max_difference(in_world, world * model), 1e-5f);
}

TEST(Skinning, ParallelBigMeshMatchesThePointByPointBlend) {
    const MeshAsset m = random_mesh(50'000, 8, 7);  // above the parallel threshold
    const auto bones = random_transforms(8, 8);
    Matrix3X p, n, again, again_n;
    skin_mesh(m, bones, Affine3::Identity(), p, n);
    skin_mesh(m, bones, Affine3::Identity(), again, again_n);
    EXPECT_TRUE(p == again);  // deterministic bytes
    for (Eigen::Index j = 0; j < m.bind_positions.cols(); j += 997) {
        Vec3 expected = Vec3::Zero();
        for (int k = 0; k < 4; ++k) expected += m.bone_weights(k, j) * (bones[std::size_t(m.bone_indices(k, j))] * Vec3(m.bind_positions.col(j)));
        EXPECT_LE((p.col(j) - expected).norm(), 1e-5f) << j;
    }
}

}  // namespace
}  // namespace drape
