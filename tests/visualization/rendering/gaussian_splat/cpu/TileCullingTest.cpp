// Tile culling (shader::TileRowSpan): a tile of a splat's 3DGS rectangle may only be dropped
// when no pixel of it can blend the splat. Checked by brute force in double precision: at
// every pixel of every dropped tile, alpha = o exp(-q / 2) stays below the composite's 1/255
// with a 0.1% allowance for float32 rounding (the culling's own margin is about 0.5% in
// alpha, so a missing margin fails here). The composite's per-block skip is checked the same way.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "GaussianSplatCompositeContract.h"
#include "SplatTestScene.h"
#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Composite.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
using namespace visualization::rendering::cpu;

struct CullingCounts {
    int64_t rect_tiles = 0;
    int64_t kept_tiles = 0;
    int64_t missed_tiles = 0;  // dropped although a pixel blends: must stay 0
};

// Largest alpha the composite could give the splat over the pixels [x0, x1) x [y0, y1)
// (integer pixel positions), in double.
double MaxAlphaInRect(const ProjectedSplat& s, int x0, int y0, int x1, int y1) {
    double best = 0.0;
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            const double dx = s.x - x, dy = s.y - y;
            const double q = s.conic_a * dx * dx + 2.0 * s.conic_b * dx * dy + s.conic_c * dy * dy;
            best = std::max(best, s.opacity * std::exp(-0.5 * q));
        }
    }
    return best;
}

// The same over the tile's pixels inside the image.
double MaxAlphaInTile(const ProjectedSplat& s, int tx, int ty, int width, int height) {
    return MaxAlphaInRect(s, tx * kTileSize, ty * kTileSize, std::min((tx + 1) * kTileSize, width),
                          std::min((ty + 1) * kTileSize, height));
}

constexpr double kBlendThreshold = (1.0 / 255.0) * (1.0 - 1e-3);

CullingCounts CheckCulling(const std::vector<ProjectedSplat>& splats, int width, int height) {
    CullingCounts counts;
    for (const ProjectedSplat& s : splats) {
        if (!s.IsVisible()) continue;
        int64_t kept = 0;
        for (int ty = s.rect_min_y; ty < s.rect_max_y; ++ty) {
            const auto [first, last] = s.RowSpan(ty);
            EXPECT_TRUE(first >= s.rect_min_x && first <= last && last <= s.rect_max_x);
            kept += last - first;
            for (int tx = s.rect_min_x; tx < s.rect_max_x; ++tx) {
                ++counts.rect_tiles;
                if (tx >= first && tx < last) continue;
                if (MaxAlphaInTile(s, tx, ty, width, height) >= kBlendThreshold) {
                    ++counts.missed_tiles;
                }
            }
        }
        EXPECT_EQ(kept, s.NumEntries());
        counts.kept_tiles += kept;
    }
    return counts;
}

// Needles, discs and blobs at every orientation and opacity, many of them crossing tile
// borders at grazing angles; correlations |rho| up to 1 - 1e-6.
std::vector<TestSplat> RandomSplats(int n, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<TestSplat> splats(n);
    for (TestSplat& s : splats) {
        s.position = Eigen::Vector3d(u(rng) * 4 - 2, u(rng) * 4 - 2, 3 + u(rng) * 6);
        for (int k = 0; k < 3; ++k) s.scale[k] = std::pow(10.0, -3.5 + 3.3 * u(rng));
        s.rot = Eigen::Vector4d(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5);
        s.opacity = std::pow(10.0, -3.0 * u(rng));  // 0.001 .. 1
    }
    return splats;
}

TEST(CpuTileCulling, RandomSplatsLoseNoBlendingTile) {
    const camera::PinholeCamera cam = MakeTestCamera(203, 157);
    for (bool antialias : {false, true}) {
        RenderConfig config;
        config.antialias = antialias;
        const auto splats = ProjectSplats(MakeCloud(RandomSplats(3000, 7)), cam, config);
        const CullingCounts c = CheckCulling(splats, cam.width, cam.height);
        EXPECT_EQ(c.missed_tiles, 0) << "antialias " << antialias;
        EXPECT_GT(c.rect_tiles, 10000);
        // Low-opacity and oblique splats fill little of their square.
        EXPECT_LT(c.kept_tiles, c.rect_tiles * 9 / 10);
        std::cout << "[tile culling] random, antialias " << antialias << ": kept " << c.kept_tiles
                  << " of " << c.rect_tiles << " rectangle tiles\n";
    }
}

TEST(CpuTileCulling, TransparentSplatEmitsNothing) {
    // alpha <= o < 1/255 everywhere: no tile can blend, yet the splat stays visible
    // (it is sorted like any other; it only emits no entries).
    TestSplat faint;
    faint.scale = {0.5, 0.5, 0.5};
    faint.opacity = 0.003;
    const auto splats = ProjectSplats(MakeCloud({faint}), MakeTestCamera(), RenderConfig{});
    ASSERT_TRUE(splats[0].IsVisible());
    EXPECT_EQ(splats[0].NumTiles(), 16);
    EXPECT_EQ(splats[0].NumEntries(), 0);
}

TEST(CpuTileCulling, PlaybotLosesNoBlendingTile) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(DataPath("playbot/playbot_31k.ply"), cloud);
    const auto views = camera::ReadCamerasJson(DataPath("playbot/cameras.json"));
    const camera::PinholeCamera cam = views.at(0).camera;
    const auto splats = ProjectSplats(cloud, cam, RenderConfig{});
    const CullingCounts c = CheckCulling(splats, cam.width, cam.height);
    EXPECT_EQ(c.missed_tiles, 0);
    std::cout << "[tile culling] playbot_31k view 0 " << cam.width << "x" << cam.height << ": kept "
              << c.kept_tiles << " of " << c.rect_tiles << " rectangle tiles\n";
    EXPECT_LT(c.kept_tiles, c.rect_tiles);
}

// The whole 3DGS rectangles, as before culling: counting sort by tile of the depth order.
TileLists RectangleLists(const std::vector<ProjectedSplat>& splats, const TileGrid& grid) {
    TileLists lists;
    lists.grid = grid;
    std::vector<std::vector<uint32_t>> tiles(grid.NumTiles());
    for (uint32_t i : SortVisibleByDepth(splats)) {
        const ProjectedSplat& s = splats[i];
        for (int ty = s.rect_min_y; ty < s.rect_max_y; ++ty) {
            for (int tx = s.rect_min_x; tx < s.rect_max_x; ++tx) {
                tiles[int64_t(ty) * grid.tiles_x + tx].push_back(i);
            }
        }
    }
    lists.offsets.push_back(0);
    for (const auto& t : tiles) {
        lists.splat_indices.insert(lists.splat_indices.end(), t.begin(), t.end());
        lists.offsets.push_back(lists.splat_indices.size());
    }
    return lists;
}

// The composite's per-block skip (shader::CompositeBlockMask): in every kept tile, a pixel
// block whose bit is clear must not hold a pixel that blends the splat, on the same brute
// force as the tiles. Counts (rect_tiles, kept_tiles, missed_tiles) are blocks here.
CullingCounts CheckBlockMasks(const std::vector<ProjectedSplat>& splats) {
    using namespace shader;
    CullingCounts counts;
    for (const ProjectedSplat& s : splats) {
        if (!s.IsVisible()) continue;
        const float t =
            TileCullThreshold(float(s.opacity), float(s.conic_a), float(s.conic_c), float(s.det_q));
        for (int ty = s.rect_min_y; ty < s.rect_max_y; ++ty) {
            const auto [first, last] = s.RowSpan(ty);
            for (int tx = first; tx < last; ++tx) {
                const int x0 = tx * kTileSize, y0 = ty * kTileSize;
                const uint32_t mask =
                    CompositeBlockMask(float(s.x), float(s.y), float(s.conic_a), float(s.conic_b),
                                       float(s.conic_c), float(s.det_q), t, float(x0), float(y0));
                EXPECT_EQ(mask >> kCompositeBlocks, 0u);
                for (uint32_t k = 0; k < kCompositeBlocks; ++k) {
                    ++counts.rect_tiles;
                    if ((mask >> k) & 1u) {
                        ++counts.kept_tiles;
                        continue;
                    }
                    const int bx = x0 + int(k % kCompositeBlocksX * kCompositeBlockWidth);
                    const int by = y0 + int(k / kCompositeBlocksX * kCompositeBlockHeight);
                    if (MaxAlphaInRect(s, bx, by, bx + int(kCompositeBlockWidth),
                                       by + int(kCompositeBlockHeight)) >= kBlendThreshold) {
                        ++counts.missed_tiles;
                    }
                }
            }
        }
    }
    return counts;
}

TEST(CpuTileCulling, BlockMasksLoseNoBlendingBlock) {
    const camera::PinholeCamera cam = MakeTestCamera(203, 157);
    for (bool antialias : {false, true}) {
        RenderConfig config;
        config.antialias = antialias;
        const auto splats = ProjectSplats(MakeCloud(RandomSplats(3000, 11)), cam, config);
        const CullingCounts c = CheckBlockMasks(splats);
        EXPECT_EQ(c.missed_tiles, 0) << "antialias " << antialias;
        EXPECT_GT(c.rect_tiles, 10000);
        EXPECT_LT(c.kept_tiles, c.rect_tiles * 3 / 4);
        std::cout << "[block masks] random, antialias " << antialias << ": kept " << c.kept_tiles
                  << " of " << c.rect_tiles << " blocks of kept tiles\n";
    }
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(DataPath("playbot/playbot_31k.ply"), cloud);
    const camera::PinholeCamera view =
        camera::ReadCamerasJson(DataPath("playbot/cameras.json")).at(0).camera;
    const CullingCounts c = CheckBlockMasks(ProjectSplats(cloud, view, RenderConfig{}));
    EXPECT_EQ(c.missed_tiles, 0);
    EXPECT_LT(c.kept_tiles, c.rect_tiles * 3 / 4);
    std::cout << "[block masks] playbot_31k view 0: kept " << c.kept_tiles << " of " << c.rect_tiles
              << " blocks of kept tiles\n";
}

// End to end: compositing only the kept tiles gives bit for bit the image (colour, expected
// and median depth) of compositing the whole rectangles, on a real scene.
TEST(CpuTileCulling, PlaybotImageIsBitIdentical) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(DataPath("playbot/playbot_31k.ply"), cloud);
    const camera::PinholeCamera cam =
        camera::ReadCamerasJson(DataPath("playbot/cameras.json")).at(0).camera.Resized(240, 240);
    const RenderConfig config;
    const auto splats = ProjectSplats(cloud, cam, config);
    const TileGrid grid = TileGrid::ForImage(cam.width, cam.height);
    const TileLists culled = BuildTileLists(splats, grid, config);
    const TileLists whole = RectangleLists(splats, grid);
    ASSERT_LT(culled.NumEntries(), whole.NumEntries() * 3 / 4);
    RenderOutput a, b;
    CompositeTiles(splats, culled, cam.width, cam.height, config, CompositeInputs{}, a);
    CompositeTiles(splats, whole, cam.width, cam.height, config, CompositeInputs{}, b);
    const auto same = [](const t::geometry::Image& x, const t::geometry::Image& y) {
        return x.GetRows() == y.GetRows() && x.GetCols() == y.GetCols() &&
               x.GetChannels() == y.GetChannels() &&
               std::memcmp(x.Data<float>(), y.Data<float>(),
                           size_t(x.GetRows()) * x.GetCols() * x.GetChannels() * 4) == 0;
    };
    EXPECT_TRUE(same(a.color, b.color));
    EXPECT_TRUE(same(a.depth_expected, b.depth_expected));
    EXPECT_TRUE(same(a.depth_median, b.depth_median));
    std::cout << "[tile culling] playbot_31k 240x240: " << culled.NumEntries() << " entries of "
              << whole.NumEntries() << ", identical image\n";
}

}  // namespace
}  // namespace tests
}  // namespace open3d
