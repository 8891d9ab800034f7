// The per-tile lists: every visible splat appears in exactly the tiles of its rectangle,
// each tile is in composite order (float32 depth, then splat index), limits set the flag.
#include <gtest/gtest.h>

#include <cmath>

#include <set>

#include "SplatTestScene.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"

namespace open3d {
namespace tests {

using namespace visualization::rendering;
using namespace visualization::rendering::cpu;

TEST(CpuTileLists, ListsMatchRectanglesAndAreSortedByDepth) {
    const auto cloud = CreateDefaultGaussianSplatScene();
    const auto cam = GetDefaultSceneCamera(160, 120);
    const auto splats = ProjectSplats(cloud, cam, RenderConfig{});
    const TileGrid grid = TileGrid::ForImage(160, 120);
    const TileLists lists = BuildTileLists(splats, grid, RenderConfig{});
    EXPECT_EQ(lists.error_flags, 0u);
    int64_t expected_entries = 0;
    for (const auto& s : splats) expected_entries += s.IsVisible() ? s.NumEntries() : 0;
    EXPECT_EQ(lists.NumEntries(), expected_entries);
    ASSERT_GT(expected_entries, 1000);
    for (int64_t t = 0; t < grid.NumTiles(); ++t) {
        const int tx = static_cast<int>(t % grid.tiles_x), ty = static_cast<int>(t / grid.tiles_x);
        for (uint64_t k = lists.offsets[t]; k < lists.offsets[t + 1]; ++k) {
            const ProjectedSplat& s = splats[lists.splat_indices[k]];
            ASSERT_TRUE(s.IsVisible());
            ASSERT_TRUE(tx >= s.rect_min_x && tx < s.rect_max_x && ty >= s.rect_min_y &&
                        ty < s.rect_max_y);
            const auto [first, last] = s.RowSpan(ty);
            ASSERT_TRUE(tx >= first && tx < last);
            if (k > lists.offsets[t]) {
                const uint32_t prev = lists.splat_indices[k - 1];
                const float d0 = splats[prev].sort_depth;
                const float d1 = s.sort_depth;
                // The float32 sort depth is the double depth to float rounding: measured
                // relative difference <= 2.4e-7 over this scene; 1e-6 allowed.
                ASSERT_NEAR(d1, s.depth, 1e-6 * s.depth);
                ASSERT_TRUE(d0 < d1 || (d0 == d1 && prev < lists.splat_indices[k]));
            }
        }
    }
}

TEST(CpuTileLists, FloatDepthTiesFallBackToSplatIndex) {
    // Equal float32 sort depths: index order decides, whatever the double depths say.
    std::vector<ProjectedSplat> splats(2);
    splats[0].cull = splats[1].cull = CullReason::kVisible;
    splats[0].depth = 5.0 + 1e-8;
    splats[1].depth = 5.0;
    splats[0].sort_depth = splats[1].sort_depth = 5.0f;
    EXPECT_EQ(SortVisibleByDepth(splats), (std::vector<uint32_t>{0, 1}));
    splats[0].sort_depth = std::nextafter(5.0f, 6.0f);  // one ulp farther
    EXPECT_EQ(SortVisibleByDepth(splats), (std::vector<uint32_t>{1, 0}));
}

TEST(CpuTileLists, CapacityLimitsDropEntriesAndFlag) {
    TestSplat big;
    big.scale = {0.5, 0.5, 0.5};  // covers all 16 tiles of 64x64
    const auto splats = ProjectSplats(MakeCloud({big}), MakeTestCamera(), RenderConfig{});
    ASSERT_EQ(splats[0].NumTiles(), 16);
    ASSERT_EQ(splats[0].NumEntries(), 16);
    RenderConfig config;
    config.max_tiles_per_splat = 15;
    TileLists lists = BuildTileLists(splats, TileGrid::ForImage(64, 64), config);
    EXPECT_EQ(lists.NumEntries(), 0);
    EXPECT_EQ(lists.error_flags, kEntriesDropped);
    config = RenderConfig{};
    config.max_tile_entries_total = 10;
    lists = BuildTileLists(splats, TileGrid::ForImage(64, 64), config);
    EXPECT_EQ(lists.error_flags, kEntriesDropped);
    config = RenderConfig{};
    lists = BuildTileLists(splats, TileGrid::ForImage(64, 64), config);
    EXPECT_EQ(lists.NumEntries(), 16);
    EXPECT_EQ(lists.error_flags, 0u);
}

}  // namespace tests
}  // namespace open3d
