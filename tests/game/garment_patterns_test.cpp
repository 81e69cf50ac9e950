// Garments cut from flat pattern pieces (game/garment_patterns.hpp) and gridded from their
// files: the pieces are found and sewn side by side into one grid, closed where the garment
// goes round the body; the committed assets/garments/ files are the generator's; the skirts
// walk within the contract.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>

#include "drape/engine/assets/garment_file.hpp"
#include "drape/game/contract.hpp"
#include "drape/game/garment_patterns.hpp"
#include "drape/game/sample_scene.hpp"
#include "drape/game/stats.hpp"
#include "drape/game/world.hpp"
#include "drape/systems/cloth/garment_from_mesh.hpp"
#include "tests/test_paths.hpp"
#include "tests/figures.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

const fs::path garments_dir = test::source_dir() / "assets" / "garments";

// The narrowest and the widest gap between neighbouring lines of a grid over the median
// one: a seam sewn shut keeps its lines as close as the rest, and once.
std::pair<Real, Real> line_gaps_over_median(const GridGarment& g) {
    const int n = g.warp_lines, m = g.particles_per_line;
    std::vector<Real> gaps;
    for (int line = 0; line < n; ++line) {
        if (!g.closed && line + 1 == n) break;
        const int next = (line + 1) % n;
        Real gap = 0;
        for (int row = 0; row < m; ++row) gap = std::max(gap, (g.grid_positions.col(line * m + row) - g.grid_positions.col(next * m + row)).norm());
        gaps.push_back(gap);
    }
    std::vector<Real> sorted = gaps;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const Real median = sorted[sorted.size() / 2];
    return {*std::min_element(gaps.begin(), gaps.end()) / median, *std::max_element(gaps.begin(), gaps.end()) / median};
}

TEST(GarmentPatterns, PiecesAreSewnIntoOneGridClosedWhereTheyGoRoundTheBody) {
    auto cut = cut_garments(sample_scene());
    ASSERT_TRUE(cut) << cut.error().message;
    const std::map<std::string, std::pair<int, bool>> designed = {
        {"flared_skirt", {4, true}}, {"wrap_skirt", {1, false}}, {"panel_dress", {2, true}}, {"cape", {1, false}}};
    ASSERT_EQ(cut->size(), designed.size());
    for (const CutGarment& g : *cut) {
        SCOPED_TRACE(g.name);
        ASSERT_TRUE(designed.contains(g.name));
        EXPECT_EQ(g.panels, designed.at(g.name).first);
        EXPECT_EQ(g.closed, designed.at(g.name).second);
        auto grid = grid_from_mesh(g.mesh, {}, g.name);
        ASSERT_TRUE(grid) << grid.error().message;
        EXPECT_EQ(grid->grid.closed, g.closed) << grid->how;
        EXPECT_NE(grid->how.find(std::to_string(g.panels) + (g.panels == 1 ? " panel" : " panels")), std::string::npos) << grid->how;
        EXPECT_EQ((grid->grid.warp_lines - (g.closed ? 0 : 1)) % grid->grid.weft_stride, 0);
        // Held along its whole top edge (one row, painted), nothing else.
        EXPECT_EQ(std::count(grid->grid.pinned.begin(), grid->grid.pinned.end(), 1), grid->grid.warp_lines);
        const auto [narrowest, widest] = line_gaps_over_median(grid->grid);
        EXPECT_LT(widest, Real(2)) << "a seam left open";
        EXPECT_GT(narrowest, Real(0.3)) << "a seam's line twice";
    }
}

TEST(GarmentPatterns, TheCommittedFilesAreTheGeneratorsAndTheSkirtsWalkWithinTheContract) {
    auto cut = cut_garments(sample_scene());
    ASSERT_TRUE(cut) << cut.error().message;
    for (const CutGarment& g : *cut) {
        SCOPED_TRACE(g.name);
        auto file = import_garment_mesh(garments_dir / (g.name + ".glb"));
        ASSERT_TRUE(file) << file.error().message;
        // The same mesh; its places within 2 mm: the cut is measured on the body's fit, which
        // rounds differently on another CPU (0.7 mm apart in a build without -march=native).
        ASSERT_EQ(file->positions.cols(), g.mesh.positions.cols()) << "regenerate: drape make-garments --out assets/garments";
        EXPECT_EQ(file->indices, g.mesh.indices);
        EXPECT_LT((file->positions - g.mesh.positions).cwiseAbs().maxCoeff(), Real(0.002));
        EXPECT_LT((file->uvs - g.mesh.uvs).cwiseAbs().maxCoeff(), Real(0.001));  // 2 mm of fabric
        ASSERT_FALSE(g.mesh.base_color.empty()) << "each fabric has its print";
        EXPECT_EQ(file->base_color.width, g.mesh.base_color.width);
        EXPECT_EQ(file->base_color.rgba, g.mesh.base_color.rgba);
    }
    // The two skirts on the default avatar's walk (the panel dress and the cape are not yet
    // within it: docs/garments.md). Labelled `figures`: the short form walks the first for 36
    // frames and asserts that they run clean.
    const char* const skirts[] = {"flared_skirt", "wrap_skirt"};
    for (const char* name : test::cases(skirts)) {
        SCOPED_TRACE(name);
        SceneDescription scene = sample_scene();
        scene.garments = {GarmentDescription{}};
        scene.garments[0].file = garments_dir / (std::string(name) + ".glb");
        auto world = build_world(scene, {});
        ASSERT_TRUE(world) << world.error().message;
        for (int frame = 0; frame < test::frames(240); ++frame) ASSERT_TRUE(step_world(*world, 1.0 / 60.0));
        const GarmentStats stats = run_stats(*world).garments.at(0);
        EXPECT_EQ(stats.nonfinite, 0u);
        if (test::short_form()) continue;
        EXPECT_TRUE(contract_breaches(stats).empty()) << garment_verdict(name, stats);
    }
}

}  // namespace
}  // namespace drape
