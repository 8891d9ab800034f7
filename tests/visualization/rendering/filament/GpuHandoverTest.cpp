// The hand-over from GL's mesh view to Vulkan's composite (SplatTargets::SignalMeshDrawn):
// where Vulkan exports and GL imports semaphores and Filament's thread can be reached, GL
// signals a semaphore after the mesh view and the composite waits for it on the GPU;
// elsewhere, and with OPEN3D_GL_VK_SEMAPHORES=0 (set here for the reference), the host waits.
// Both must give the same frame, byte for byte, over several
// frames (a binary semaphore signalled and waited once per frame), colour and depth. On
// llvmpipe and lavapipe (no semaphore export) both frames take the host wait; on NVIDIA this
// checks the semaphore.
#include <gtest/gtest.h>

#include <filament/Engine.h>
#include <filament/SwapChain.h>

#include <cstring>
#include <vector>

#include "TestUtility.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatInterop.h"
#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using rendering::FrameRequest;
using rendering::FrameResult;
using rendering::SplatSharing;

bool SameBytes(const t::geometry::Image& a, const t::geometry::Image& b) {
    const core::Tensor& x = a.AsTensor();
    const core::Tensor& y = b.AsTensor();
    return x.GetShape() == y.GetShape() && x.GetDtype() == y.GetDtype() &&
           std::memcmp(x.RawData(), y.RawData(), x.NumBytes()) == 0;
}

TEST_F(FilamentTest, GpuHandoverGivesTheHostWaitsFrame) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(64, 48);
    rendering::FilamentScene& scene = MakeScene();
    AddSplatsAroundRedSphere(scene);

    // Three frames of colour, then one of depth, on one view.
    struct Frames {
        t::geometry::Image color[3];
        t::geometry::Image depth;
        bool handover = false;
    };
    auto render = [&](rendering::FilamentView& view) {
        Frames frames;
        FrameRequest color;
        color.read_color = true;
        for (t::geometry::Image& image : frames.color) {
            const FrameResult result = renderer_->Draw(scene, view, color);
            EXPECT_TRUE(result.splats_drawn && result.scene_depth_used);
            image = result.color;
        }
        FrameRequest depth;
        depth.read_depth = true;
        depth.depth_near = 0.5f;
        depth.depth_far = 5.0f;
        frames.depth = renderer_->Draw(scene, view, depth).linear_depth;
        frames.handover = view.GetSplatTargets()->HasGpuHandover();
        EXPECT_TRUE(view.GetSplatTargets()->IsZeroCopy());
        return frames;
    };
    Frames gpu;
    {
        ScopedEnvironment on("OPEN3D_GL_VK_SEMAPHORES", "1");
        gpu = render(MakeView(camera, SplatSharing::kZeroCopy));
    }
    Frames host;
    {
        ScopedEnvironment off("OPEN3D_GL_VK_SEMAPHORES", "0");
        host = render(MakeView(camera, SplatSharing::kZeroCopy));
    }
    const bool available =
        engine_->CanRunOnDriverThread() &&
        rendering::vulkan::QueryInteropSupport(scene.GetBackend()).external_semaphore_fd &&
        engine_->GetGl().HasSemaphoreFd();
    EXPECT_EQ(gpu.handover, available);
    EXPECT_FALSE(host.handover);
    for (int i = 0; i < 3; ++i) {
        EXPECT_TRUE(SameBytes(gpu.color[i], host.color[i])) << "colour frame " << i;
        EXPECT_TRUE(SameBytes(gpu.color[i], gpu.color[0])) << "colour frame " << i;
    }
    EXPECT_TRUE(SameBytes(gpu.depth, host.depth));
}

// Presented frames (read_screen alone, so the host reads no splat image): with the hand-over
// the composite signals "splats drawn", the host does not wait for it and GL's compose view
// waits on the GPU; the screens must equal the host-waited ones byte for byte, frame by frame,
// with the camera moving so that a compose reading the previous frame's splats would differ.
TEST_F(FilamentTest, GpuHandoverPresentsTheHostWaitsScreens) {
    rendering::FilamentScene& scene = MakeScene();
    AddSplatsAroundRedSphere(scene);
    constexpr int kFrames = 3;
    auto present = [&](const char* semaphores, bool& handover) {
        ScopedEnvironment env("OPEN3D_GL_VK_SEMAPHORES", semaphores);
        camera::PinholeCamera camera = MakeFilamentTestCamera(64, 48);
        rendering::FilamentView& view = MakeView(camera, SplatSharing::kZeroCopy);
        filament::Engine& engine = engine_->GetEngine();
        filament::SwapChain* swap_chain = engine.createSwapChain(
            uint32_t(camera.width), uint32_t(camera.height), filament::SwapChain::CONFIG_READABLE);
        std::vector<t::geometry::Image> screens;
        FrameRequest request;
        request.read_screen = true;
        for (int i = 0; i < kFrames; ++i) {
            camera.world_to_camera(0, 3) = 0.05 * i;  // the view slides sideways each frame
            view.SetCamera(camera);
            const FrameResult result = renderer_->Draw(scene, view, request, swap_chain);
            EXPECT_TRUE(result.splats_drawn);
            screens.push_back(result.screen);
        }
        handover = view.GetSplatTargets()->HasGpuHandover();
        engine.destroy(swap_chain);
        engine.flushAndWait();
        return screens;
    };
    bool gpu_handover = false, host_handover = true;
    const std::vector<t::geometry::Image> gpu = present("1", gpu_handover);
    const std::vector<t::geometry::Image> host = present("0", host_handover);
    EXPECT_FALSE(host_handover);
    const bool available =
        engine_->CanRunOnDriverThread() &&
        rendering::vulkan::QueryInteropSupport(scene.GetBackend()).external_semaphore_fd &&
        engine_->GetGl().HasSemaphoreFd();
    EXPECT_EQ(gpu_handover, available);
    ASSERT_EQ(gpu.size(), host.size());
    for (int i = 0; i < kFrames; ++i) {
        ASSERT_FALSE(gpu[i].IsEmpty());
        EXPECT_TRUE(SameBytes(gpu[i], host[i])) << "screen " << i;
    }
    EXPECT_FALSE(SameBytes(host[0], host[kFrames - 1]));  // the camera moved the picture
}

}  // namespace
}  // namespace tests
}  // namespace open3d
