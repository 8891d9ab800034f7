// A composite the host does not wait for (GaussianSplatVulkanBackend::RenderComposite with a
// sink that signals a semaphore and reads nothing back, as a presented Filament frame with
// the GL hand-over does): it must write the same picture as the read-back path, be waited for
// before anything reuses what it touches, and report its GPU time with the next such frame.
// Any device runs it: the semaphore here is a plain one, waited for by an empty submission
// as GL would wait for the exported one. The fixture's validation checks the semaphore use.
#include <gtest/gtest.h>

#include <cstring>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Image.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
using vulkan::CompositeSink;

constexpr int kWidth = 64;
constexpr int kHeight = 48;

// Composites into its own RGBA32F image (the read-back path's format, so both must agree
// bit for bit) and signals `signal` without reading back.
class SignallingSink final : public CompositeSink {
public:
    SignallingSink(const vulkan::VulkanContext& context, VkSemaphore signal)
        : color_(context, kWidth, kHeight, VK_FORMAT_R32G32B32A32_SFLOAT,
                 VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                     VK_IMAGE_USAGE_TRANSFER_DST_BIT),
          signal_(signal) {}

    const vulkan::Image& ColorTarget() const override { return color_; }
    void AdjustParams(vulkan::CompositeParams&) const override {}
    void RecordBefore(const Frame& frame) override {
        vulkan::RecordImageBarrier(frame.cmd, color_.Get(), VK_IMAGE_ASPECT_COLOR_BIT,
                                   VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                                   VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, frame.write_stage,
                                   frame.write_access);
    }
    void RecordAfter(const Frame&) override {}
    void ReadBack() override { ++read_backs; }
    VkSemaphore TakeSignalSemaphore() override { return signal_; }
    VkSemaphore TakeWaitSemaphore() override {
        const VkSemaphore wait = wait_;
        wait_ = VK_NULL_HANDLE;  // one wait per signal
        return wait;
    }
    bool ReadsBack() const override { return false; }
    bool SubmitsBehindGeometry() const override { return behind_geometry; }
    // The next submission waits for `semaphore` (signalled once, as GL signals "mesh drawn").
    void WaitNextFor(VkSemaphore semaphore) { wait_ = semaphore; }

    // The colour image's floats, copied after everything submitted so far.
    std::vector<float> Read(const vulkan::VulkanContext& context, vulkan::CommandPool& pool) {
        const size_t floats = size_t(kWidth) * kHeight * 4;
        vulkan::Buffer buffer(context, floats * sizeof(float), VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                              vulkan::MemoryUsage::kHostReadback);
        vulkan::SubmitAndWait(context, pool, [&](VkCommandBuffer cmd) {
            vulkan::RecordImageBarrier(
                cmd, color_.Get(), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                VK_ACCESS_2_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                VK_ACCESS_2_TRANSFER_READ_BIT);
            vulkan::RecordCopyToBuffer(cmd, color_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                                       buffer.Get());
            vulkan::RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT,
                                        VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                        VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        });
        std::vector<float> values(floats);
        std::memcpy(values.data(), buffer.GetMapped(), floats * sizeof(float));
        return values;
    }

    int read_backs = 0;
    bool behind_geometry = false;

private:
    vulkan::Image color_;
    VkSemaphore signal_;
    VkSemaphore wait_ = VK_NULL_HANDLE;
};

// An empty submission that waits for `wait` and signals `signal` (either may be null), waited
// for on the host: what GL does with the exported semaphores.
void SubmitEmpty(const vulkan::VulkanContext& context, vulkan::CommandPool& pool, VkSemaphore wait,
                 VkSemaphore signal) {
    vulkan::CommandBuffer cmd = pool.Allocate();
    cmd.Begin();
    cmd.End();
    vulkan::UniqueFence fence = vulkan::CreateFence(context);
    vulkan::SubmitToQueue(context.GetQueue(), cmd.Get(), fence.Get(), wait,
                          VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, signal);
    vulkan::Wait(context, fence.Get());
}

// GL's wait for "splats drawn": one wait per signal.
void ConsumeSignal(const vulkan::VulkanContext& context, vulkan::CommandPool& pool,
                   VkSemaphore semaphore) {
    SubmitEmpty(context, pool, semaphore, VK_NULL_HANDLE);
}

// GL's "mesh drawn" signal, once per frame.
void Signal(const vulkan::VulkanContext& context, vulkan::CommandPool& pool,
            VkSemaphore semaphore) {
    SubmitEmpty(context, pool, VK_NULL_HANDLE, semaphore);
}

// The read-back path's composite of `backend`'s last geometry stage, checked to hold the
// same floats as `colour` (same shader, inputs and format).
RenderOutput ExpectReadbackPathGives(vulkan::GaussianSplatVulkanBackend& backend,
                                     const std::vector<float>& colour) {
    RenderOutput readback;
    backend.RenderCompositeStage(readback);
    EXPECT_EQ(readback.color.NumPixels(), int64_t(kWidth) * kHeight);
    if (readback.color.NumPixels() == int64_t(kWidth) * kHeight) {
        EXPECT_EQ(
            std::memcmp(colour.data(), readback.color.Data<float>(), colour.size() * sizeof(float)),
            0);
    }
    return readback;
}

class DeferredComposite : public VulkanTest {
protected:
    // A backend holding playbot_31k (read once; its cameras into cameras_).
    auto PlaybotBackend() {
        if (cameras_.empty()) {
            t::io::ReadPointCloud(DataPath("playbot/playbot_31k.ply"), cloud_);
            cameras_ = camera::ReadCamerasJson(DataPath("playbot/cameras.json"));
        }
        auto backend = MakeBackend();
        backend->SetScene(cloud_);
        return backend;
    }
    t::geometry::PointCloud cloud_;
    std::vector<camera::CameraView> cameras_;
};

TEST_F(DeferredComposite, WritesTheReadbackPathsColourAndIsWaitedForBeforeReuse) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    auto backend = PlaybotBackend();
    const auto& cameras = cameras_;
    RenderConfig config;
    const vulkan::UniqueSemaphore semaphore = vulkan::CreateBinarySemaphore(Context());
    SignallingSink sink(Context(), semaphore.Get());

    // Two views, each: the deferred composite, then the read-back path of the same geometry
    // stage (which first waits for the deferred one).
    for (int view : {0, 8}) {
        SCOPED_TRACE(view);
        const camera::PinholeCamera camera = cameras.at(view).camera.Resized(kWidth, kHeight);
        backend->RenderGeometryStage(camera, config);
        const int64_t before = backend->GetCounters().composites;
        const RenderStats deferred = backend->RenderComposite(sink);
        EXPECT_EQ(backend->GetCounters().composites, before + 1);
        EXPECT_EQ(sink.read_backs, view == 0 ? 1 : 2);  // called, reads nothing
        EXPECT_GT(deferred.num_tile_entries, 0);
        // The first deferred frame has no finished one before it to report.
        if (view == 0) EXPECT_EQ(deferred.gpu_composite_ms, 0.0);
        if (view != 0) EXPECT_GT(deferred.gpu_composite_ms, 0.0);
        ConsumeSignal(Context(), Pool(), semaphore.Get());
        backend->WaitForComposite();
        const std::vector<float> colour = sink.Read(Context(), Pool());

        const RenderOutput readback = ExpectReadbackPathGives(*backend, colour);
        EXPECT_GT(readback.stats.gpu_composite_ms, 0.0);
    }

    // A deferred frame left in flight is waited for by the next geometry stage (which rewrites
    // the entries it reads) and by the backend's destruction.
    const camera::PinholeCamera camera = cameras.at(0).camera.Resized(kWidth, kHeight);
    backend->RenderGeometryStage(camera, config);
    backend->RenderComposite(sink);
    ConsumeSignal(Context(), Pool(), semaphore.Get());
    backend->RenderGeometryStage(cameras.at(8).camera.Resized(kWidth, kHeight), config);
    RenderOutput last;
    backend->RenderCompositeStage(last);
    EXPECT_GT(last.stats.num_tile_entries, 0);
}

// Frames as the GL hand-over runs them: GL's "mesh drawn" signal, then the composite that
// waits for it, submitted behind its geometry stage and not waited for. From the second
// frame on, the geometry stage is held and submitted by the composite behind that semaphore
// (so a frame's Vulkan work runs as one block after GL's). Each frame must equal the
// read-back path's frame of its camera, float for float, while the camera moves.
TEST_F(DeferredComposite, GeometryStagesHeldBehindGlsSemaphoreDrawEveryFrame) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    auto backend = PlaybotBackend();
    const auto& cameras = cameras_;
    auto reference = PlaybotBackend();
    const vulkan::UniqueSemaphore mesh_drawn = vulkan::CreateBinarySemaphore(Context());
    const vulkan::UniqueSemaphore splats_drawn = vulkan::CreateBinarySemaphore(Context());
    SignallingSink sink(Context(), splats_drawn.Get());
    sink.behind_geometry = true;
    const std::vector<int> views = {0, 3, 8, 11};
    for (size_t i = 0; i < views.size(); ++i) {
        SCOPED_TRACE(views[i]);
        const camera::PinholeCamera camera = cameras.at(views[i]).camera.Resized(kWidth, kHeight);
        backend->RenderGeometryStage(camera, {});
        Signal(Context(), Pool(), mesh_drawn.Get());
        sink.WaitNextFor(mesh_drawn.Get());
        backend->RenderComposite(sink);
        EXPECT_EQ(backend->GetCounters().held_geometry_stages, int64_t(i));
        ConsumeSignal(Context(), Pool(), splats_drawn.Get());
        backend->WaitForComposite();
        const std::vector<float> colour = sink.Read(Context(), Pool());

        reference->RenderGeometryStage(camera, {});
        ExpectReadbackPathGives(*reference, colour);
    }
    // The first frame's counters were read before its composite, the later ones after.
    EXPECT_EQ(backend->GetCounters().capacity_growths, 0);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
