// A character's parts marked hidden (SkinnedMesh::hidden: a garment modelled into its file
// while a simulated one is worn over it) are not in the draw list; the others are.
#include <gtest/gtest.h>

#include <memory>
#include <string_view>

#include "drape/components/skinned_mesh.hpp"
#include "drape/engine/core/registry.hpp"
#include "drape/systems/render_system.hpp"

namespace drape {
namespace {

// Two triangles, each its own part: "Body" and "Skirt".
std::shared_ptr<MeshAsset> two_parts() {
    auto mesh = std::make_shared<MeshAsset>();
    mesh->bind_positions.resize(3, 6);
    mesh->bind_positions << 0, 1, 0, 2, 3, 2, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0;
    mesh->bind_normals = Matrix3X::Zero(3, 6);
    mesh->bind_normals.row(2).setOnes();
    mesh->bone_indices.setZero(4, 6);
    mesh->bone_weights.setZero(4, 6);
    mesh->bone_weights.row(0).setOnes();
    mesh->indices = {0, 1, 2, 3, 4, 5};
    mesh->submeshes = {{"Body", 0, 3}, {"Skirt", 3, 3}};
    return mesh;
}

TEST(HiddenParts, AHiddenPartIsNotDrawnTheOthersAre) {
    Registry registry;
    const Entity e = registry.create();
    SkinnedMesh& skin = registry.emplace<SkinnedMesh>(e);
    skin.mesh = two_parts();
    skin.positions = skin.mesh->bind_positions;
    skin.normals = skin.mesh->bind_normals;
    DrawList all;
    build_draw_list(registry, false, all);
    ASSERT_EQ(all.meshes.size(), 1u);
    ASSERT_EQ(all.meshes[0].ranges.size(), 2u);

    registry.get<SkinnedMesh>(e).hidden = {0, 1};
    DrawList shown;
    build_draw_list(registry, false, shown);
    ASSERT_EQ(shown.meshes.size(), 1u);
    ASSERT_EQ(shown.meshes[0].ranges.size(), 1u);
    EXPECT_EQ(shown.meshes[0].ranges[0].name, std::string_view("Body"));
    EXPECT_TRUE(shown.problems.empty());

    // Every part hidden: nothing of it is drawn (no ranges would draw the whole mesh).
    registry.get<SkinnedMesh>(e).hidden = {1, 1};
    DrawList none;
    build_draw_list(registry, false, none);
    EXPECT_TRUE(none.meshes.empty());
}

}  // namespace
}  // namespace drape
