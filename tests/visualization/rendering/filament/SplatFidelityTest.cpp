// Integration adds no error: the splat part of RenderToImage (no mesh, black background)
// equals the headless Vulkan renderer's image of the same camera, on a real scene; the
// zero-copy path is the one taken on llvmpipe + lavapipe, and the host-copy fallback gives
// the same image.
#include <gtest/gtest.h>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/t/io/PointCloudIO.h"
#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using SplatFidelity = FilamentTest;

TEST_F(SplatFidelity, RenderToImageEqualsHeadlessRenderer) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(DataPath("playbot/playbot_31k.ply"), cloud);
    const camera::PinholeCamera camera =
        camera::ReadCamerasJson(DataPath("playbot/cameras.json")).at(0).camera.Resized(96, 64);

    // Expected: the headless renderer's float colour over opaque black, rounded to 8 bits.
    const rendering::RenderOutput headless = RenderHeadless(cloud, camera);
    t::geometry::Image expected(camera.height, camera.width, 3, core::Dtype::UInt8);
    for (int64_t i = 0; i < expected.NumPixels(); ++i) {
        const auto want = ExpectedOver(headless.color.Data<float>() + 4 * i, {0, 0, 0, 1});
        for (int c = 0; c < 3; ++c) expected.Data<uint8_t>()[3 * i + c] = uint8_t(want[c]);
    }

    rendering::Open3DSceneOptions zero_copy;
    zero_copy.sharing = rendering::SplatSharing::kZeroCopy;
    rendering::Open3DSceneOptions host_copy;
    host_copy.sharing = rendering::SplatSharing::kHostCopy;
    for (const auto& options : {zero_copy, host_copy}) {
        rendering::Open3DScene& scene = MakeOpen3DScene(options);
        scene.AddGeometry("playbot", cloud);
        scene.SetupCamera(camera);
        const t::geometry::Image image = scene.RenderToImage();
        EXPECT_EQ(scene.GetView().GetSplatTargets()->IsZeroCopy(),
                  options.sharing == rendering::SplatSharing::kZeroCopy);
        EXPECT_FALSE(scene.GetLastFrame().scene_depth_used);
        EXPECT_GT(scene.GetLastFrame().splat_stats.num_visible, 10000);
        // Zero-copy stores the colour as RGBA16F (relative error <= 2^-10), host copy
        // keeps float32: at most 1 LSB after rounding; PSNR measured 58-inf dB.
        const auto m = t::geometry::ComputeImageErrorMetrics(image, expected, 255.0, 0.0);
        EXPECT_LE(m.max_abs_error, 1.0);
        EXPECT_GE(m.psnr_db, 50.0);
    }
}

}  // namespace
}  // namespace tests
}  // namespace open3d
