// The interactive path: the compose view (mesh colour blit + splat overlay material,
// premultiplied "over", y flipped) drawn on a swap chain gives the same picture as the
// offscreen host blend, for both ways of sharing the splat image.
#include <gtest/gtest.h>

#include <filament/Engine.h>
#include <filament/SwapChain.h>

#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using rendering::SplatSharing;

class InteractivePath : public FilamentTest, public ::testing::WithParamInterface<SplatSharing> {};

TEST_P(InteractivePath, SwapChainMatchesOffscreenBlend) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(48, 32);
    rendering::FilamentScene& scene = MakeScene();
    scene.AddGeometry("wall", MakeSplatWall(4.0, 3.0, 16, Eigen::Vector3d(0.1, 0.2, 0.9)));
    scene.AddGeometry("blob", MakeSplatBlob(-0.3, -0.2, 1.3, 0.1, Eigen::Vector3d(0.9, 0.9, 0.2)));
    AddRedSphere(scene);
    rendering::FilamentView& view = MakeView(camera, GetParam());
    view.SetBackground(Eigen::Vector4f(0.2f, 0.3f, 0.4f, 1.0f));
    filament::Engine& engine = engine_->GetEngine();
    filament::SwapChain* swap_chain = engine.createSwapChain(
        uint32_t(camera.width), uint32_t(camera.height), filament::SwapChain::CONFIG_READABLE);
    rendering::FrameRequest request;
    request.read_color = true;
    request.read_screen = true;
    const rendering::FrameResult frame = renderer_->Draw(scene, view, request, swap_chain);
    engine.destroy(swap_chain);
    engine.flushAndWait();
    ASSERT_EQ(frame.screen.NumPixels(), frame.color.NumPixels());
    const uint8_t* screen = frame.screen.Data<uint8_t>();
    const uint8_t* offscreen = frame.color.Data<uint8_t>();
    // The GPU blends 8-bit mesh colour with the fp16 overlay in the 8-bit target; the host
    // blends in float from the same inputs: at most 1 LSB apart (measured: 1).
    int worst = 0, red = 0;
    for (int64_t i = 0; i < frame.color.NumPixels(); ++i) {
        for (int c = 0; c < 3; ++c) {
            worst = std::max(worst, std::abs(int(screen[4 * i + c]) - int(offscreen[4 * i + c])));
        }
        red += screen[4 * i] == 255 && screen[4 * i + 1] == 0;
    }
    EXPECT_LE(worst, 1);
    EXPECT_GT(red, 50);  // the sphere shows, so the picture is not trivially equal
}

INSTANTIATE_TEST_SUITE_P(Sharing, InteractivePath,
                         ::testing::Values(SplatSharing::kZeroCopy, SplatSharing::kHostCopy),
                         SharingTestName);

}  // namespace
}  // namespace tests
}  // namespace open3d
