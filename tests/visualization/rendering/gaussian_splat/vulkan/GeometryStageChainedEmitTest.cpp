// The chained emit (gaussian_emit_chained.comp: the tile-count scan, the capacity cut and the
// emit in one dispatch by decoupled look-back, with the sorts' histograms counted by their
// producers) against the separate passes (scan levels, dispatch args, emit, the sorts'
// histogram dispatches), which the multi-pass sorts run. Both orders are stable, so every
// readback must be equal word for word: the depth-ordered list, the entries, the counters
// and the flags, across capacities that cut the list in its first block, in a later one,
// one entry short of everything and exactly at everything, and with max_tiles_per_splat
// dropping splats. The one-sweep geometry stage runs here with one lavapipe thread; its odd
// blocks publish only their own totals, so the look-backs walk across blocks (with
// workgroups in order they would otherwise always find an inclusive prefix next door).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "GaussianSplatTileListContract.h"
#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/CommandTally.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"
#include "visualization/rendering/gaussian_splat/vulkan/support/GaussianGeometryStageRunner.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
using visualization::rendering::vulkan::GaussianGeometryStageRunner;
using visualization::rendering::vulkan::GeometryStageOptions;
using visualization::rendering::vulkan::GeometryStageReadback;
using visualization::rendering::vulkan::RadixSort;

class GeometryStageChainedEmit : public VulkanTest {
protected:
    static constexpr int kChainedDispatches = 1 + 4 + 1 + 1 + 1;

    static void SetUpTestSuite() { SetUpTestSuiteOnOneLavapipeThread(); }

    void SetUp() override {
        VulkanTest::SetUp();
        if (IsSkipped() || HasFatalFailure()) return;
        OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
        OPEN3D_REQUIRE_DATA("playbot/cameras.json");
        t::geometry::PointCloud cloud;
        t::io::ReadPointCloud(DataPath("playbot/playbot_31k.ply"), cloud);
        packed_ = PackGaussianSplatAttrs(cloud);
        // 31k list slots: 122 blocks of the chained emit.
        camera_ = camera::ReadCamerasJson(DataPath("playbot/cameras.json"))
                      .at(0)
                      .camera.Resized(160, 120);
    }

    // One run of each way at `capacity` entries.
    void ExpectSameReadbacks(uint32_t capacity, const RenderConfig& config,
                             const std::string& what) {
        GeometryStageOptions separate_options;
        separate_options.sort = RadixSort::Algorithm::kMultiPass;
        GeometryStageOptions chained_options;
        chained_options.sort = RadixSort::Algorithm::kOneSweep;
        chained_options.chained_odd_blocks_aggregate_only = true;
        GaussianGeometryStageRunner separate(Context(), packed_, capacity, separate_options);
        GaussianGeometryStageRunner chained(Context(), packed_, capacity, chained_options);
        int want_dispatches = 0, got_dispatches = 0;
        const GeometryStageReadback want = Run(separate, config, want_dispatches);
        const GeometryStageReadback got = Run(chained, config, got_dispatches);
        SCOPED_TRACE(what + ", capacity " + std::to_string(capacity));
        // The chained way really ran: the projection, the depth sort's four scatters, the
        // chained emit, and the tile sort's one scatter (80 tiles: 7 key bits) with its copy
        // back (an odd pass count); no histogram, scan or dispatch-args dispatch.
        EXPECT_EQ(got_dispatches, kChainedDispatches);
        EXPECT_GT(want_dispatches, got_dispatches);
        EXPECT_EQ(got.counters.visible_count, want.counters.visible_count);
        EXPECT_EQ(got.counters.requested_entries, want.counters.requested_entries);
        EXPECT_EQ(got.counters.entry_count, want.counters.entry_count);
        EXPECT_EQ(got.counters.error_flags, want.counters.error_flags);
        EXPECT_EQ(got.visible_in_depth_order, want.visible_in_depth_order);
        EXPECT_EQ(got.entry_tiles, want.entry_tiles);
        EXPECT_EQ(got.entry_splats, want.entry_splats);
    }

    // Runs one view and counts the dispatches its recording holds.
    GeometryStageReadback Run(GaussianGeometryStageRunner& runner, const RenderConfig& config,
                              int& dispatches) {
        visualization::rendering::vulkan::CommandTally tally;
        GeometryStageReadback readback = runner.Run(camera_, config, false);
        dispatches = tally.Counts().dispatches;
        return readback;
    }

    PackedGaussianSplats packed_;
    camera::PinholeCamera camera_;
};

TEST_F(GeometryStageChainedEmit, MatchesTheSeparatePassesAtEveryCapacity) {
    // The uncut total first (the separate passes' count of entries).
    GeometryStageOptions options;
    options.sort = RadixSort::Algorithm::kMultiPass;
    GaussianGeometryStageRunner uncut(Context(), packed_, 1u << 20, options);
    const GeometryStageReadback all = uncut.Run(camera_, RenderConfig{}, false);
    ASSERT_EQ(all.counters.error_flags, 0u);
    const uint32_t total = all.counters.entry_count;
    ASSERT_GT(all.counters.visible_count, 20u * shader::kEmitWorkgroupSize)
        << "the list must span many blocks of the chained emit";
    // 1: the first splat with entries cannot fit (the cut in block 0); a third and two
    // thirds: cuts in later blocks; total - 1: the last splat drops; total and more:
    // everything fits and the last slot writes the count.
    for (uint32_t capacity :
         {1u, total / 3, 2 * total / 3, total - 1, total, total + 1, 1u << 20}) {
        ExpectSameReadbacks(capacity, RenderConfig{}, "playbot_31k");
    }
}

TEST_F(GeometryStageChainedEmit, DropsSplatsOverMaxTilesPerSplatAsTheSeparatePassesDo) {
    RenderConfig config;
    config.max_tiles_per_splat = 2;  // splats over two tiles count nothing and flag
    ExpectSameReadbacks(1u << 20, config, "max_tiles_per_splat 2");
}

TEST_F(GeometryStageChainedEmit, SortsTheSameWithEveryBlockPublishingItsPrefix) {
    // Without the test switch: each look-back stops at the block before it.
    GeometryStageOptions separate_options;
    separate_options.sort = RadixSort::Algorithm::kMultiPass;
    GeometryStageOptions chained_options;
    chained_options.sort = RadixSort::Algorithm::kOneSweep;
    GaussianGeometryStageRunner separate(Context(), packed_, 1u << 20, separate_options);
    GaussianGeometryStageRunner chained(Context(), packed_, 1u << 20, chained_options);
    int want_dispatches = 0, got_dispatches = 0;
    const GeometryStageReadback want = Run(separate, RenderConfig{}, want_dispatches);
    const GeometryStageReadback got = Run(chained, RenderConfig{}, got_dispatches);
    EXPECT_EQ(got_dispatches, kChainedDispatches);
    EXPECT_GT(want_dispatches, got_dispatches);
    EXPECT_EQ(got.counters.entry_count, want.counters.entry_count);
    EXPECT_EQ(got.entry_tiles, want.entry_tiles);
    EXPECT_EQ(got.entry_splats, want.entry_splats);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
