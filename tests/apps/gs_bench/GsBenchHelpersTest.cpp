// gs-bench's helpers beside the binary (cpp/apps/gs_bench): budgets as --lod-budgets reads and
// prints them, the supersampled view and the filtered reference --lod-supersample compares
// with, drawn in tiles.
#include <gtest/gtest.h>

#include "BenchScenes.h"
#include "LodBudgets.h"
#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "t/io/RandomSplatCloud.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;

TEST(GsBenchHelpers, BudgetsReadAndPrint) {
    EXPECT_EQ(bench::ParseBudgets("500k,1M,2.5M,3001"),
              (std::vector<int64_t>{500000, 1000000, 2500000, 3001}));
    for (const char* bad : {"", "1.5", "0", "2X", "1k,", "-3"}) {
        EXPECT_THROW(bench::ParseBudgets(bad), core::Open3DError) << bad;
    }
    EXPECT_EQ(bench::BudgetLabel(500000), "500k");
    EXPECT_EQ(bench::BudgetLabel(12500), "12.5k");
    EXPECT_EQ(bench::BudgetLabel(2500000), "2.5M");
    EXPECT_EQ(bench::BudgetLabel(3001), "3001");
}

camera::PinholeCamera SmallView() {
    camera::PinholeCamera cam;
    cam.width = 32;
    cam.height = 24;
    cam.fx = cam.fy = 30.0;
    cam.cx = 15.5;
    cam.cy = 11.5;
    cam.world_to_camera(2, 3) = 40.0;
    return cam;
}

TEST(GsBenchHelpers, TheSupersampledViewPutsEachPixelsBlockOnIt) {
    // A point on pixel (x, y)'s centre lands on the centre of that pixel's block of s x s:
    // fine pixel s (x + 0.5) - 0.5.
    const camera::PinholeCamera cam = SmallView();
    const camera::PinholeCamera fine = bench::SupersampledView(cam, 3);
    EXPECT_EQ(fine.width, 96);
    EXPECT_EQ(fine.height, 72);
    const double X = 2.0, Y = -1.5, Z = 40.0;
    const double x = cam.fx * X / Z + cam.cx, y = cam.fy * Y / Z + cam.cy;
    EXPECT_NEAR(fine.fx * X / Z + fine.cx, 3 * (x + 0.5) - 0.5, 1e-12);
    EXPECT_NEAR(fine.fy * Y / Z + fine.cy, 3 * (y + 0.5) - 0.5, 1e-12);
}

TEST(GsBenchHelpers, TheFilteredReferenceDrawnInTilesIsTheWholeSupersampledRender) {
    // Splats of at most 0.3 units (a few pixels of the finest view): none reaches into a tile
    // from beyond the tile's Jacobian guard band, where the tile and the whole view clamp
    // differently (the band follows each view's own field of view).
    t::geometry::PointCloud scene = t::io::RandomCloud(2000, 1, 3);
    core::Tensor& scale = scene.GetPointAttr("scale");
    for (int64_t i = 0; i < scale.NumElements(); ++i) {
        scale.Data<float>()[i] = 0.05f + 0.25f * float((i * 7919) % 101) / 100.0f;
    }
    const camera::PinholeCamera cam = SmallView();
    cpu::CpuBackend backend;
    backend.SetScene(scene);
    const RenderConfig config;
    for (int s : {2, 4}) {
        const t::geometry::Image tiled = bench::FilteredReference(backend, cam, s, config);
        const t::geometry::Image whole =
            backend.Render(bench::SupersampledView(cam, s), config).color.BoxDownsample(s);
        ASSERT_EQ(tiled.GetRows(), 24);
        ASSERT_EQ(tiled.GetCols(), 32);
        // The whole view's principal point is centred, so its float32 threshold decisions
        // (alpha >= 1/255) read the original rasterizer's pixel centres; the tiles' are not,
        // so theirs read their own rounded centres, and a few blends flip: measured 87.0 dB
        // (s = 2) and 78.2 dB (s = 4).
        EXPECT_GE(t::geometry::ComputePSNR(tiled, whole, 1.0), 75.0) << s;
        // And the filter does something here: the exact render differs by more than 1/255.
        EXPECT_GT(t::geometry::ComputeMaxAbsError(tiled, backend.Render(cam, config).color),
                  1.0 / 255.0);
    }
    ExpectErrorContaining([&] { bench::FilteredReference(backend, cam, 5, config); },
                          "does not divide the view's 32 x 24 pixels");
}

}  // namespace
}  // namespace tests
}  // namespace open3d
