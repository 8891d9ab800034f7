// Depth-aware compositing through Filament: a red sphere in front of a wall of splats hides
// them exactly where it covers them, splats in front of it stay visible, and the merged
// depth is the sphere's where the sphere is and the splats' elsewhere.
#include <gtest/gtest.h>

#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using rendering::FrameRequest;
using rendering::FrameResult;

class OcclusionTest : public FilamentTest,
                      public ::testing::WithParamInterface<rendering::SplatSharing> {};

TEST_P(OcclusionTest, SphereHidesSplatsBehindIt) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(64, 48);
    rendering::FilamentScene& scene = MakeScene();
    scene.AddGeometry("wall", MakeSplatWall(4.0, 3.0, 24, Eigen::Vector3d(0.1, 0.2, 0.9)));
    AddRedSphere(scene);
    rendering::FilamentView& view = MakeView(camera, GetParam());
    FrameRequest request;
    request.read_color = true;
    request.read_depth = true;
    const FrameResult frame = renderer_->Draw(scene, view, request);
    EXPECT_TRUE(frame.splats_drawn);
    EXPECT_TRUE(frame.scene_depth_used);
    const uint8_t* rgba = frame.color.Data<uint8_t>();
    const float* z = frame.linear_depth.Data<float>();
    const auto at = [&](int x, int y) { return size_t(y) * camera.width + x; };
    const int cx = camera.width / 2, cy = camera.height / 2;
    EXPECT_EQ(rgba[4 * at(cx, cy) + 0], 255);
    EXPECT_EQ(rgba[4 * at(cx, cy) + 1], 0);
    EXPECT_EQ(rgba[4 * at(cx, cy) + 2], 0);
    EXPECT_NEAR(z[at(cx, cy)], SphereDepthAt(camera, cx, cy), 2e-3);
    EXPECT_GT(rgba[4 * at(2, 2) + 2], 150);
    EXPECT_NEAR(z[at(2, 2)], 4.0, 0.05);
}

INSTANTIATE_TEST_SUITE_P(Sharing, OcclusionTest,
                         ::testing::Values(rendering::SplatSharing::kZeroCopy,
                                           rendering::SplatSharing::kHostCopy),
                         [](const auto& info) {
                             return info.param == rendering::SplatSharing::kZeroCopy ? "ZeroCopy"
                                                                                     : "HostCopy";
                         });

}  // namespace
}  // namespace tests
}  // namespace open3d
