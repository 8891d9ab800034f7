// Per-tile bins (SortMode::kExactTileBins): tiles longer than the bin sort's shared-memory run,
// depth ties, and the order the atomics fill a bin in must all give the CPU reference's lists entry
// for entry (cpu::BuildTileLists: ascending float32 depth, ties by splat index).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "GaussianSplatTileListContract.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"
#include "visualization/rendering/gaussian_splat/cpu/SplatTestScene.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"
#include "visualization/rendering/gaussian_splat/vulkan/support/GaussianGeometryStageRunner.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
using visualization::rendering::vulkan::GaussianGeometryStageRunner;
using visualization::rendering::vulkan::GeometryStageReadback;

class GeometryStageBins : public VulkanTest {};

RenderConfig TileBins() {
    RenderConfig config;
    config.sort_mode = SortMode::kExactTileBins;
    return config;
}

using TileListsByTile = std::vector<std::vector<uint32_t>>;

TileListsByTile GpuLists(const GeometryStageReadback& gpu, size_t tiles) {
    TileListsByTile out(tiles);
    for (size_t k = 0; k < gpu.entry_tiles.size(); ++k) {
        out.at(gpu.entry_tiles[k]).push_back(gpu.entry_splats[k]);
    }
    return out;
}

TileListsByTile CpuLists(const t::geometry::PointCloud& cloud, const camera::PinholeCamera& cam,
                         const RenderConfig& config) {
    const cpu::TileLists lists =
        cpu::BuildTileLists(cpu::ProjectSplats(cloud, cam, config),
                            cpu::TileGrid::ForImage(cam.width, cam.height), config);
    TileListsByTile out(lists.offsets.size() - 1);
    for (size_t t = 0; t + 1 < lists.offsets.size(); ++t) {
        out[t].assign(lists.splat_indices.begin() + lists.offsets[t],
                      lists.splat_indices.begin() + lists.offsets[t + 1]);
    }
    return out;
}

// `count` small splats over a 48x32 image (3x2 tiles), at `depths` distinct depths only,
// so most of a tile's entries tie with others on depth; shuffled so index order and depth
// order disagree.
t::geometry::PointCloud CrowdedScene(int count, int depths, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> x(-0.2, 0.2), y(-0.12, 0.12);
    std::uniform_int_distribution<int> level(0, depths - 1);
    std::vector<TestSplat> splats(count);
    for (TestSplat& s : splats) {
        const double z = 5.0 + 0.25 * level(rng);
        s.position = Eigen::Vector3d(x(rng) * z / 5.0, y(rng) * z / 5.0, z);
        s.scale = Eigen::Vector3d(0.01, 0.01, 0.01);
        s.opacity = 0.3;
    }
    return MakeCloud(splats);
}

TEST_F(GeometryStageBins, LongTilesAndTiesGiveTheReferenceLists) {
    // 24,000 splats in 6 tiles: the tiles hold more than the shared-memory run (2,048 on
    // lavapipe, 4,096 on NVIDIA), so the in-place stages run; 7 depths make ties the rule.
    const auto cloud = CrowdedScene(24000, 7, 11);
    const auto cam = MakeTestCamera(48, 32);
    GaussianGeometryStageRunner runner(Context(), PackGaussianSplatAttrs(cloud), 1u << 16);
    const GeometryStageReadback gpu = runner.Run(cam, TileBins());
    ASSERT_EQ(gpu.counters.error_flags, 0u);
    const TileListsByTile want = CpuLists(cloud, cam, RenderConfig{});
    size_t longest = 0;
    for (const auto& tile : want) longest = std::max(longest, tile.size());
    ASSERT_GT(longest, size_t(shader::kBinSortCapacityLarge)) << "no tile takes the long path";
    EXPECT_EQ(GpuLists(gpu, want.size()), want);
}

TEST_F(GeometryStageBins, ShortTilesOfEverySizeGiveTheReferenceLists) {
    // Tiles from a few entries to about lavapipe's run of 2,048: the power-of-two padding
    // of the shared-memory sort, on both sides of the run on lavapipe.
    for (int count : {3, 40, 300, 2000, 8000}) {
        const auto cloud = CrowdedScene(count, 3, 100 + count);
        const auto cam = MakeTestCamera(48, 32);
        GaussianGeometryStageRunner runner(Context(), PackGaussianSplatAttrs(cloud), 1u << 16);
        const GeometryStageReadback gpu = runner.Run(cam, TileBins());
        const TileListsByTile want = CpuLists(cloud, cam, RenderConfig{});
        EXPECT_EQ(GpuLists(gpu, want.size()), want) << count << " splats";
    }
}

}  // namespace
}  // namespace tests
}  // namespace open3d
