// Vulkan geometry stage features beyond the plain projection: SH degree as a
// specialisation constant (degree 0 reads no SH), the visibility mask, capacity
// limits with GPU error flags warned once per view, an empty view, and the
// compact precision.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <iostream>
#include <limits>
#include <string_view>

#include "GaussianSplatTileListContract.h"
#include "GeometryStageComparison.h"
#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Logging.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "visualization/rendering/gaussian_splat/cpu/SplatTestScene.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"
#include "visualization/rendering/gaussian_splat/vulkan/support/GaussianGeometryStageRunner.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
using visualization::rendering::vulkan::GaussianGeometryStageRunner;
using visualization::rendering::vulkan::GeometryStageReadback;

class GeometryStageFeatures : public VulkanTest {
protected:
    static void ExpectExact(const GeometryStageComparison& c) {
        std::cout << "[geometry stage] " << c.Summary() << "\n";
        EXPECT_EQ(c.cull_flips, 0) << c.Summary();
        EXPECT_EQ(c.border_splats.size(), 0u) << c.Summary();
        EXPECT_EQ(c.tiles_misordered, 0) << c.Summary();
        EXPECT_EQ(c.gpu_span_mismatches, 0) << c.Summary();
        EXPECT_EQ(c.entries_cpu, c.entries_gpu) << c.Summary();
        // Colour: measured <= 6.8e-7 with fp32 SH (GeometryStageProjectionTest); 1e-5
        // bounds it.
        EXPECT_LE(c.errors.color_abs, 1e-5) << c.Summary();
    }
};

t::geometry::PointCloud ReadScene(const std::string& relative) {
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(DataPath(relative), cloud);
    return cloud;
}

// cameras.json view 0 of playbot at a small size (the caller requires the data).
camera::PinholeCamera PlaybotView0(int width, int height) {
    return camera::ReadCamerasJson(DataPath("playbot/cameras.json"))
        .at(0)
        .camera.Resized(width, height);
}

camera::PinholeCamera LookAtCloud(int width, int height) {
    camera::LookAtCamera look;
    look.eye = {0.0, 0.0, -3.0};
    look.center = {0.0, 0.0, 0.0};
    look.up = {0, -1, 0};
    return camera::PinholeCamera::FromLookAt(look, width, height);
}

TEST_F(GeometryStageFeatures, ShDegreesZeroToThreeViaSpecialisation) {
    OPEN3D_REQUIRE_DATA("pc_short/pc_short.ply");
    const auto cloud = ReadScene("pc_short/pc_short.ply");  // SH degree 3
    ASSERT_EQ(cloud.GaussianSplatGetSHOrder(), 3);
    const PackedGaussianSplats packed = PackGaussianSplatAttrs(cloud);
    GaussianGeometryStageRunner runner(Context(), packed, 1u << 16);
    // A camera inside the cloud's bounds sees the splats from varied directions.
    const auto cam = camera::PinholeCamera::FromLookAt(
        {Eigen::Vector3d(2.0, 1.0, -2.0), Eigen::Vector3d::Zero(), Eigen::Vector3d(0, -1, 0), 60},
        96, 80);
    for (int degree = 0; degree <= 3; ++degree) {
        RenderConfig config;
        config.sh_degree = degree;
        const GeometryStageReadback gpu = runner.Run(cam, config);
        ASSERT_GT(gpu.counters.visible_count, 0u);
        ExpectExact(CompareGeometryStage(cloud, cam, config, gpu));
    }
}

TEST_F(GeometryStageFeatures, DegreeZeroReadsNoSh) {
    OPEN3D_REQUIRE_DATA("pc_short/pc_short.ply");
    const auto cloud = ReadScene("pc_short/pc_short.ply");
    const auto cam = LookAtCloud(64, 48);
    RenderConfig config;
    config.sh_degree = 0;
    // (a) An SH buffer full of NaN: evaluated at degree 0 the colours stay finite
    // and equal to the reference, so no SH word was read.
    PackedGaussianSplats packed = PackGaussianSplatAttrs(cloud);
    ASSERT_EQ(packed.sh_words_per_splat, 45u);
    std::fill(packed.sh.begin(), packed.sh.end(), 0x7FC00000u);  // quiet NaN
    GaussianGeometryStageRunner nan_runner(Context(), packed, 1u << 16);
    const GeometryStageReadback gpu = nan_runner.Run(cam, config);
    ASSERT_GT(gpu.counters.visible_count, 0u);
    for (uint32_t i : gpu.visible_in_depth_order) {
        ASSERT_TRUE(std::isfinite(gpu.projected[i].color.x)) << "splat " << i;
    }
    ExpectExact(CompareGeometryStage(cloud, cam, config, gpu));
    // (b) Packed at degree 0 there is no SH at all: nothing uploaded, a 16-byte
    // placeholder fills the binding.
    const PackedGaussianSplats dc_only = PackGaussianSplatAttrs(cloud, SplatPrecision::kExact, 0);
    EXPECT_TRUE(dc_only.sh.empty());
    EXPECT_EQ(dc_only.sh_words_per_splat, 0u);
    GaussianGeometryStageRunner dc_runner(Context(), dc_only, 1u << 16);
    ExpectExact(CompareGeometryStage(cloud, cam, config, dc_runner.Run(cam, config)));
}

TEST_F(GeometryStageFeatures, HiddenSplatsEmitNothing) {
    const auto cloud = CreateDefaultGaussianSplatScene();
    const auto cam = GetDefaultSceneCamera(128, 96);
    PackedGaussianSplats packed = PackGaussianSplatAttrs(cloud);
    std::vector<bool> hidden(cloud.NumPoints(), false);
    for (int64_t i = 0; i < cloud.NumPoints(); i += 3) {
        hidden[i] = true;
        SetSplatVisibility(packed.visibility, i, i + 1, false);
    }
    // A whole mask word (32 splats) off too, as ShowGeometry(false) on an object
    // would do.
    for (int64_t i = 64; i < 96; ++i) hidden[i] = true;
    SetSplatVisibility(packed.visibility, 64, 96, false);
    GaussianGeometryStageRunner runner(Context(), packed, 1u << 18);
    const GeometryStageReadback gpu = runner.Run(cam, RenderConfig{});
    for (uint32_t i : gpu.entry_splats) ASSERT_FALSE(hidden[i]) << "hidden splat " << i;
    for (uint32_t i : gpu.visible_in_depth_order) ASSERT_FALSE(hidden[i]);
    const GeometryStageComparison c = CompareGeometryStage(cloud, cam, RenderConfig{}, gpu, hidden);
    std::cout << "[geometry stage] " << c.Summary() << "\n";
    EXPECT_EQ(c.cull_flips, 0) << c.Summary();
    EXPECT_EQ(c.border_splats.size(), 0u) << c.Summary();
    EXPECT_EQ(c.tiles_misordered, 0) << c.Summary();
    EXPECT_EQ(c.gpu_span_mismatches, 0) << c.Summary();
    EXPECT_EQ(c.entries_cpu, c.entries_gpu) << c.Summary();

    // Showing them again (SetVisibility uploads the mask only) brings them back.
    packed.visibility.assign(packed.visibility.size(), ~0u);
    runner.SetVisibility(packed.visibility);
    const GeometryStageReadback all = runner.Run(cam, RenderConfig{});
    EXPECT_GT(all.counters.visible_count, gpu.counters.visible_count);
}

// Expected lists under the GPU capacity rule: splats emit whole, front to back,
// until the first one that does not fit; everything behind it is dropped.
std::vector<std::vector<uint32_t>> PrefixRuleLists(const GeometryStageReadback& gpu,
                                                   const std::vector<cpu::ProjectedSplat>& ref,
                                                   const cpu::TileGrid& grid,
                                                   const RenderConfig& config, uint64_t capacity) {
    std::vector<std::vector<uint32_t>> tiles(grid.NumTiles());
    uint64_t total = 0;
    for (uint32_t i : gpu.visible_in_depth_order) {
        const cpu::ProjectedSplat& s = ref[i];
        const uint64_t n = static_cast<uint64_t>(s.NumEntries());
        if (n > config.max_tiles_per_splat) continue;
        if (total + n > capacity) break;
        total += n;
        for (int ty = s.rect_min_y; ty < s.rect_max_y; ++ty) {
            const auto [first, last] = s.RowSpan(ty);
            for (int tx = first; tx < last; ++tx) tiles[ty * grid.tiles_x + tx].push_back(i);
        }
    }
    return tiles;
}

std::vector<std::vector<uint32_t>> GpuLists(const GeometryStageReadback& gpu,
                                            const cpu::TileGrid& grid) {
    std::vector<std::vector<uint32_t>> tiles(grid.NumTiles());
    for (size_t k = 0; k < gpu.entry_tiles.size(); ++k) {
        tiles.at(gpu.entry_tiles[k]).push_back(gpu.entry_splats[k]);
    }
    return tiles;
}

// Per-tile bins: a capacity drops whole tiles from the first that does not fit.
RenderConfig TileBins() {
    RenderConfig config;
    config.sort_mode = SortMode::kExactTileBins;
    return config;
}

TEST_F(GeometryStageFeatures, CapacityOverflowDropsEntriesFlagsAndWarnsOnce) {
    const auto cloud = CreateDefaultGaussianSplatScene();
    // 9,696 entries (measured; 12,228 tiles in the splats' rectangles before tile culling)
    const auto cam = GetDefaultSceneCamera(160, 120);
    const auto grid = cpu::TileGrid::ForImage(cam.width, cam.height);
    const auto ref = cpu::ProjectSplats(cloud, cam, RenderConfig{});
    const PackedGaussianSplats packed = PackGaussianSplatAttrs(cloud);

    int warnings = 0;
    core::LogSink previous = core::SetLogSink(nullptr);
    core::SetLogSink([&](core::LogLevel level, std::string_view message) {
        if (level == core::LogLevel::Warning &&
            message.find("geometry stage") != std::string_view::npos) {
            ++warnings;
        }
        if (previous) previous(level, message);
    });

    // (a) The allocation (4,096 entries) is the limit: bits 0 and 1.
    {
        GaussianGeometryStageRunner runner(Context(), packed, 4096);
        for (int frame = 0; frame < 3; ++frame) {
            const GeometryStageReadback gpu = runner.Run(cam, RenderConfig{});
            EXPECT_EQ(gpu.counters.error_flags, kEntriesDropped | kCountsClamped);
            EXPECT_LE(gpu.counters.entry_count, 4096u);
            EXPECT_GT(gpu.counters.entry_count, 4000u);
            EXPECT_EQ(gpu.counters.requested_entries, 9696u);
            EXPECT_EQ(GpuLists(gpu, grid), PrefixRuleLists(gpu, ref, grid, RenderConfig{}, 4096));
        }
    }
    EXPECT_EQ(warnings, 2) << "one warning per flag bit for the view, not one per frame";

    // (b) RenderConfig::max_tile_entries_total is the limit: bit 0 only.
    warnings = 0;
    {
        RenderConfig config;
        config.max_tile_entries_total = 5000;
        GaussianGeometryStageRunner runner(Context(), packed, 1u << 16);
        const GeometryStageReadback gpu = runner.Run(cam, config);
        EXPECT_EQ(gpu.counters.error_flags, kEntriesDropped);
        EXPECT_EQ(GpuLists(gpu, grid), PrefixRuleLists(gpu, ref, grid, config, 5000));
        runner.Run(cam, config);
    }
    EXPECT_EQ(warnings, 1);

    // (c) max_tiles_per_splat: big splats emit nothing, the rest is exactly the
    // reference.
    {
        RenderConfig config;
        config.max_tiles_per_splat = 2;
        GaussianGeometryStageRunner runner(Context(), packed, 1u << 16);
        const GeometryStageReadback gpu = runner.Run(cam, config);
        EXPECT_EQ(gpu.counters.error_flags, kEntriesDropped);
        const auto lists =
            cpu::BuildTileLists(cpu::ProjectSplats(cloud, cam, config), grid, config);
        EXPECT_EQ(gpu.counters.entry_count, static_cast<uint32_t>(lists.NumEntries()));
        EXPECT_EQ(GpuLists(gpu, grid), PrefixRuleLists(gpu, ref, grid, config, 1u << 16));
    }
    core::SetLogSink(previous);
}

TEST_F(GeometryStageFeatures, CapacityCutsTheListWhereTheScanSaysAcrossScanLevels) {
    // 31,000 list slots are 31 scan blocks under one top level: the offsets that decide
    // where the capacity cuts the list (and where each splat writes) add the block sums
    // (ScanOffset). Expected: the uncut run's lists, keeping the splats that fit whole
    // front to back, up to the first that does not.
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    OPEN3D_REQUIRE_DATA("playbot/cameras.json");
    const auto cloud = ReadScene("playbot/playbot_31k.ply");
    const auto cam = PlaybotView0(128, 96);
    const auto grid = cpu::TileGrid::ForImage(cam.width, cam.height);
    const PackedGaussianSplats packed = PackGaussianSplatAttrs(cloud);
    GaussianGeometryStageRunner uncut_runner(Context(), packed, 1u << 20);
    const GeometryStageReadback uncut = uncut_runner.Run(cam, RenderConfig{});
    ASSERT_EQ(uncut.counters.error_flags, 0u);
    ASSERT_GT(uncut.visible_in_depth_order.size(), 2u * shader::kScanBlockSize);
    std::vector<uint32_t> entries_of(cloud.NumPoints(), 0);
    for (uint32_t splat : uncut.entry_splats) ++entries_of.at(splat);
    const uint32_t capacity = uncut.counters.entry_count / 2;
    std::vector<bool> kept(entries_of.size(), false);
    uint32_t total = 0;
    size_t cut = 0;  // list position of the first splat that does not fit
    for (; cut < uncut.visible_in_depth_order.size(); ++cut) {
        const uint32_t splat = uncut.visible_in_depth_order[cut];
        if (total + entries_of[splat] > capacity) break;
        total += entries_of[splat];
        kept[splat] = true;
    }
    ASSERT_GT(cut, 2u * shader::kScanBlockSize) << "the cut must lie past the first blocks";
    std::vector<std::vector<uint32_t>> want = GpuLists(uncut, grid);
    for (auto& tile : want) {
        std::erase_if(tile, [&](uint32_t splat) { return !kept[splat]; });
    }
    GaussianGeometryStageRunner cut_runner(Context(), packed, capacity);
    const GeometryStageReadback gpu = cut_runner.Run(cam, RenderConfig{});
    EXPECT_EQ(gpu.counters.error_flags, kEntriesDropped | kCountsClamped);
    EXPECT_EQ(gpu.counters.requested_entries, uncut.counters.entry_count);
    EXPECT_EQ(gpu.counters.entry_count, total);
    EXPECT_EQ(GpuLists(gpu, grid), want);
}

TEST_F(GeometryStageFeatures, BinsKeepWholeTilesUpToTheCapacity) {
    // Per-tile bins: tiles in row-major order keep all their entries while their running
    // total fits; from the first that does not, tiles get none. Expected: the uncut run's
    // lists (which equal the global sorts', checked here too) cut that way.
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    OPEN3D_REQUIRE_DATA("playbot/cameras.json");
    const auto cloud = ReadScene("playbot/playbot_31k.ply");
    const auto cam = PlaybotView0(128, 96);
    const auto grid = cpu::TileGrid::ForImage(cam.width, cam.height);
    const PackedGaussianSplats packed = PackGaussianSplatAttrs(cloud);
    GaussianGeometryStageRunner uncut_runner(Context(), packed, 1u << 20);
    const GeometryStageReadback uncut = uncut_runner.Run(cam, TileBins());
    ASSERT_EQ(uncut.counters.error_flags, 0u);
    EXPECT_EQ(GpuLists(uncut, grid), GpuLists(uncut_runner.Run(cam, RenderConfig{}), grid));
    std::vector<std::vector<uint32_t>> want = GpuLists(uncut, grid);
    const uint32_t capacity = uncut.counters.entry_count / 2;
    uint32_t total = 0;
    size_t first_cut = want.size();
    for (size_t t = 0; t < want.size(); ++t) {
        if (first_cut == want.size() && total + want[t].size() <= capacity) {
            total += static_cast<uint32_t>(want[t].size());
        } else {
            if (first_cut == want.size()) first_cut = t;
            want[t].clear();
        }
    }
    ASSERT_GT(first_cut, 0u);
    ASSERT_LT(first_cut, want.size() - 1);
    GaussianGeometryStageRunner cut_runner(Context(), packed, capacity);
    const GeometryStageReadback gpu = cut_runner.Run(cam, TileBins());
    EXPECT_EQ(gpu.counters.error_flags, kEntriesDropped | kCountsClamped);
    EXPECT_EQ(gpu.counters.requested_entries, uncut.counters.entry_count);
    EXPECT_EQ(gpu.counters.entry_count, total);
    EXPECT_EQ(GpuLists(gpu, grid), want);
}

TEST_F(GeometryStageFeatures, NothingVisible) {
    const auto cloud = CreateDefaultGaussianSplatScene();
    auto cam = GetDefaultSceneCamera(64, 48);
    cam.world_to_camera.topRightCorner<3, 1>() += Eigen::Vector3d(0, 0, -1000);  // all behind
    GaussianGeometryStageRunner runner(Context(), PackGaussianSplatAttrs(cloud), 1024);
    const GeometryStageReadback gpu = runner.Run(cam, RenderConfig{});
    EXPECT_EQ(gpu.counters.visible_count, 0u);
    EXPECT_EQ(gpu.counters.entry_count, 0u);
    EXPECT_EQ(gpu.counters.error_flags, 0u);
}

TEST_F(GeometryStageFeatures, CompactPrecisionStaysClose) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    OPEN3D_REQUIRE_DATA("playbot/cameras.json");
    const auto cloud = ReadScene("playbot/playbot_31k.ply");
    const auto cam = PlaybotView0(128, 96);
    const PackedGaussianSplats compact = PackGaussianSplatAttrs(cloud, SplatPrecision::kCompact);
    EXPECT_LE(compact.BytesPerSplat(), 140u);
    GaussianGeometryStageRunner runner(Context(), compact, 1u << 18);
    const auto c =
        CompareGeometryStage(cloud, cam, RenderConfig{}, runner.Run(cam, RenderConfig{}));
    std::cout << "[geometry stage compact] " << c.Summary() << "\n";
    EXPECT_EQ(c.tiles_misordered, 0) << c.Summary();
    EXPECT_EQ(c.gpu_span_mismatches, 0) << c.Summary();
    EXPECT_EQ(c.visible_list_misordered, 0) << c.Summary();
    // fp16 keeps 11 significant bits. Measured on this view: conic 4.2e-3
    // relative, colour 1.0e-3, 23 radii off by one, 4 tile rects differ (2
    // entries lost); centre, depth and opacity stay fp32 (1.7e-5 px, 1.1e-7,
    // 3e-8). Bounds ~5-10x the measured values.
    EXPECT_LE(c.errors.center_px, 1e-3) << c.Summary();
    EXPECT_LE(c.errors.opacity_abs, 1e-5) << c.Summary();
    EXPECT_LE(c.errors.conic_rel, 2e-2) << c.Summary();
    EXPECT_LE(c.errors.color_abs, 1e-2) << c.Summary();
}

}  // namespace
}  // namespace tests
}  // namespace open3d
