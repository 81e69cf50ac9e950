// A game reads a garment's simulated mesh for its own renderer.
#include <gtest/gtest.h>

#include "analytic_body.hpp"
#include "drape/systems/cloth/garment_builder.hpp"
#include "drape/systems/cloth/garment_mesh.hpp"
#include "drape/systems/cloth/garment_step.hpp"

namespace drape {
namespace {

TEST(GarmentMesh, IsTheSimulatedSurfaceWithUnitNormalsFacingOut) {
    Registry registry;
    test::AnalyticBody body(registry);
    const Entity e = *attach_skirt(registry, body.character, TubeParams::skirt());
    Garment& g = registry.get<Garment>(e);
    GarmentSolver& s = registry.get<GarmentSolver>(e);
    for (int frame = 0; frame < 10; ++frame) {
        body.place(registry, (frame + 1) / 60.0, false, 1.0 / 60.0);
        step_garment(registry, g, s, 1.0 / 60.0, {});
    }
    GarmentMesh mesh;
    ASSERT_TRUE(read_garment_mesh(registry, e, mesh));
    EXPECT_TRUE(mesh.positions.isApprox(g.state.x));
    ASSERT_EQ(mesh.triangles.size(), g.fabric->triangles.size());
    EXPECT_EQ(mesh.normals.cols(), mesh.positions.cols());
    // A skirt round the body: its normals point away from the vertical axis through its
    // centre, on the whole.
    const Vec3 centre = mesh.positions.rowwise().mean();
    int outward = 0;
    for (Eigen::Index i = 0; i < mesh.positions.cols(); ++i) {
        EXPECT_NEAR(mesh.normals.col(i).norm(), 1, 1e-4);
        Vec3 radial = mesh.positions.col(i) - centre;
        radial.y() = 0;
        outward += mesh.normals.col(i).dot(radial) > 0;
    }
    EXPECT_GT(outward, 0.9 * mesh.positions.cols());
    EXPECT_TRUE(mesh.color.isApprox(g.config.color));
}

TEST(GarmentMesh, SaysWhatIsMissing) {
    Registry registry;
    GarmentMesh mesh;
    const auto none = read_garment_mesh(registry, Entity{}, mesh);
    ASSERT_FALSE(none);
    EXPECT_NE(none.error().message.find("does not exist"), std::string::npos);
    const Entity bare = registry.create();
    const auto no_garment = read_garment_mesh(registry, bare, mesh);
    ASSERT_FALSE(no_garment);
    EXPECT_NE(no_garment.error().message.find("no Garment"), std::string::npos);
    registry.emplace<Garment>(bare);
    const auto unbuilt = read_garment_mesh(registry, bare, mesh);
    ASSERT_FALSE(unbuilt);
    EXPECT_NE(unbuilt.error().message.find("not been built"), std::string::npos);
}

}  // namespace
}  // namespace drape
