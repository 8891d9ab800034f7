// Issue 8's cross-device report (not a regular test: DISABLED_ unless asked for with
// --gtest_also_run_disabled_tests). Renders geometry stage of playbot_125k view 0 at 1920x1080
// (fx = fy = fx_json * 1080 / 800), compares it with the CPU reference, and, when
// OPEN3D_STAGE_A_DUMP names a file, writes the sorted entries there ((tile, splat) uint32
// pairs) so two devices' lists can be compared entry by entry.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "GeometryStageComparison.h"
#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"
#include "visualization/rendering/gaussian_splat/vulkan/support/GaussianGeometryStageRunner.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;

class GeometryStageReport : public VulkanTest {};

TEST_F(GeometryStageReport, DISABLED_Playbot125kView0At1080p) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_125k.ply");
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(DataPath("playbot/playbot_125k.ply"), cloud);
    camera::PinholeCamera cam = camera::ReadCamerasJson(DataPath("playbot/cameras.json"))[0].camera;
    const double scale = 1080.0 / cam.height;
    cam.fx *= scale;
    cam.fy *= scale;
    cam.width = 1920;
    cam.height = 1080;
    cam.cx = (cam.width - 1) / 2.0;
    cam.cy = (cam.height - 1) / 2.0;
    const RenderConfig config;
    vulkan::GaussianGeometryStageRunner runner(Context(), PackGaussianSplatAttrs(cloud), 1u << 24);
    const vulkan::GeometryStageReadback gpu = runner.Run(cam, config);
    const GeometryStageComparison c = CompareGeometryStage(cloud, cam, config, gpu);
    std::cout << "[geometry stage report] playbot_125k view 0 1920x1080: " << c.Summary()
              << " | submit-to-fence " << gpu.geometry_stage_ms << " ms\n";
    EXPECT_EQ(c.tiles_misordered, 0);
    EXPECT_EQ(c.gpu_span_mismatches, 0);
    EXPECT_EQ(c.cull_flips_unexplained, 0);
    if (const char* path = std::getenv("OPEN3D_STAGE_A_DUMP")) {
        FILE* f = std::fopen(path, "wb");
        ASSERT_NE(f, nullptr) << path;
        for (size_t i = 0; i < gpu.entry_tiles.size(); ++i) {
            const uint32_t pair[2] = {gpu.entry_tiles[i], gpu.entry_splats[i]};
            std::fwrite(pair, sizeof(pair), 1, f);
        }
        std::fclose(f);
    }
}

}  // namespace
}  // namespace tests
}  // namespace open3d
