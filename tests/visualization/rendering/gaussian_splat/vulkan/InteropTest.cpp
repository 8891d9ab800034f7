// The zero-copy interop targets (GaussianSplatInterop.h): exported memory, and composites into
// the shared RGBA16F / D32 images against the headless readback path of the same backend
// (RenderCompositeStage, RGBA32F). The shared depth is written with UploadDepth as Filament
// would write it (reversed Z, GL row order). Runs on the fixture's device through borrowed
// handles, so the fixture's validation (with synchronization validation) covers every
// ownership transfer.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatInterop.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
using vulkan::GaussianSplatVulkanBackend;
using vulkan::InteropCompositeRequest;
using vulkan::InteropFrame;
using vulkan::InteropTargets;

constexpr const char* kScene = "playbot/playbot_31k.ply";
constexpr int kWidth = 64;
constexpr int kHeight = 48;

// lavapipe converts float to half rounding toward zero (Vulkan allows it), so a stored value
// is within 2^-10 of the float32 one, relatively; below half's normal range (2^-14) the step is
// 2^-24 absolute. Measured on playbot_31k view 0 at 64x48: largest relative error 9.7e-4
// (< 2^-10 = 9.8e-4), i.e. truncation, not round-to-nearest's 2^-11.
constexpr double kHalfRelative = 1.0 / 1024.0;
constexpr double kHalfSubnormalStep = 1.0 / (1 << 24);

// Largest |a - b| / max(|b|, 2^-14) over all elements, and whether every element is within
// the truncation bound above.
struct HalfComparison {
    double max_relative = 0.0;
    bool within_bound = true;
};
HalfComparison CompareHalf(const t::geometry::Image& half, const t::geometry::Image& full) {
    HalfComparison result;
    const auto& a = half.AsTensor();
    const auto& b = full.AsTensor();
    EXPECT_EQ(a.GetShape(), b.GetShape());
    if (a.GetShape() != b.GetShape()) return {1.0, false};
    for (int64_t i = 0; i < a.NumElements(); ++i) {
        const double x = a.Data<float>()[i], y = b.Data<float>()[i];
        const double error = std::abs(x - y);
        result.max_relative = std::max(result.max_relative, error / std::max(std::abs(y), 0x1p-14));
        if (error > std::max(std::abs(y) * kHalfRelative, kHalfSubnormalStep)) {
            result.within_bound = false;
        }
    }
    return result;
}

// A wall at view z `z` over the left half and the top two thirds of the image (top row
// first): asymmetric in y, so a missing flip of GL's bottom-first rows shows.
t::geometry::Image Wall(float z) {
    t::geometry::Image wall(kHeight, kWidth, 1, core::Dtype::Float32);
    for (int y = 0; y < kHeight * 2 / 3; ++y) {
        for (int x = 0; x < kWidth / 2; ++x) wall.At<float>(y, x) = z;
    }
    return wall;
}

// What Filament's depth attachment holds for `view_z`: d = near / z (0 = nothing drawn),
// bottom row first.
std::vector<float> ToReversedZ(const t::geometry::Image& view_z, float near) {
    std::vector<float> d(size_t(kWidth) * kHeight, 0.0f);
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            const float z = view_z.At<float>(y, x);
            d[size_t(kHeight - 1 - y) * kWidth + x] = z > 0.0f ? near / z : 0.0f;
        }
    }
    return d;
}

// Mean expected depth of the covered pixels: the middle of the splats' depth range.
float MeanDepth(const RenderOutput& out) {
    double sum = 0.0;
    int64_t covered = 0;
    for (int64_t i = 0; i < out.depth_expected.NumPixels(); ++i) {
        const float z = out.depth_expected.Data<float>()[i];
        if (z > 0.0f) {
            sum += z;
            ++covered;
        }
    }
    EXPECT_GT(covered, 0);
    return covered > 0 ? float(sum / covered) : 1.0f;
}

class Interop : public VulkanTest {
protected:
    void SetUp() override {
        VulkanTest::SetUp();
        if (IsSkipped() || HasFatalFailure()) return;
        if (!Context().SupportsExternalMemoryFd()) {
            GTEST_SKIP() << Context().GetDeviceInfo().name << " has no VK_KHR_external_memory_fd";
        }
    }

    std::unique_ptr<GaussianSplatVulkanBackend> MakeBackend(uint32_t entry_capacity = 1u << 22,
                                                            bool export_enabled = true) {
        vulkan::BorrowedVulkanHandles handles = BorrowedHandles();
        handles.external_memory_fd_enabled = export_enabled;
        handles.external_semaphore_fd_enabled =
            export_enabled && handles.external_semaphore_fd_enabled;
        return std::make_unique<GaussianSplatVulkanBackend>(
            vulkan::VulkanContext::CreateFromBorrowed(handles), entry_capacity);
    }

    // playbot_31k, view 0 at 64x48, set on a fresh backend with geometry stage run.
    std::unique_ptr<GaussianSplatVulkanBackend> PlaybotBackend() {
        t::geometry::PointCloud cloud;
        t::io::ReadPointCloud(DataPath(kScene), cloud);
        camera_ = camera::ReadCamerasJson(DataPath("playbot/cameras.json"))
                      .at(0)
                      .camera.Resized(kWidth, kHeight);
        auto backend = MakeBackend();
        backend->SetScene(cloud);
        backend->RenderGeometryStage(camera_, config_);
        return backend;
    }

    camera::PinholeCamera camera_;
    RenderConfig config_;  // black background: the headless colour is the premultiplied one
};

TEST_F(Interop, SupportIsReportedForTheVulkanBackendOnly) {
    auto backend = MakeBackend();
    const vulkan::InteropSupport support = vulkan::QueryInteropSupport(*backend);
    EXPECT_TRUE(support.external_memory_fd);
    const std::array<uint8_t, 16> zero{};
    EXPECT_NE(support.device_uuid, zero);
    EXPECT_NE(support.driver_uuid, zero);
    EXPECT_EQ(support.device_uuid, Context().GetDeviceInfo().device_uuid);

    // Borrowed handles without the extension flag: no export (a context cannot tell).
    const auto without = vulkan::QueryInteropSupport(*MakeBackend(1u << 22, false));
    EXPECT_FALSE(without.external_memory_fd);
    EXPECT_EQ(without.device_uuid, support.device_uuid);

    const auto cpu = vulkan::QueryInteropSupport(*CreateGaussianSplatBackend("cpu"));
    EXPECT_FALSE(cpu.external_memory_fd);
    EXPECT_EQ(cpu.device_uuid, zero);
    EXPECT_EQ(cpu.driver_uuid, zero);
    auto cpu_backend = CreateGaussianSplatBackend("cpu");
    EXPECT_THROW(InteropTargets(*cpu_backend, 8, 8), core::Open3DError);
    auto no_export = MakeBackend(1u << 22, false);
    EXPECT_THROW(InteropTargets(*no_export, 8, 8), core::Open3DError);
    EXPECT_THROW(InteropTargets(*backend, 0, 8), core::Open3DError);
}

TEST_F(Interop, ExportsGiveNewDescriptorsOfWholeAllocations) {
    auto backend = MakeBackend();
    InteropTargets targets(*backend, kWidth, kHeight);
    EXPECT_EQ(targets.GetWidth(), uint32_t(kWidth));
    EXPECT_EQ(targets.GetHeight(), uint32_t(kHeight));
    const vulkan::ExportedImageMemory color = targets.ExportColor();
    const vulkan::ExportedImageMemory depth = targets.ExportDepth();
    const vulkan::ExportedImageMemory color_again = targets.ExportColor();
    for (const auto* memory : {&color, &depth, &color_again}) {
        ASSERT_GE(memory->fd, 0);
        struct stat info {};
        EXPECT_EQ(fstat(memory->fd, &info), 0);
        EXPECT_TRUE(memory->dedicated);
    }
    EXPECT_NE(color.fd, depth.fd);
    EXPECT_NE(color.fd, color_again.fd);
    EXPECT_GE(color.size, uint64_t(kWidth) * kHeight * 8);  // RGBA16F
    EXPECT_GE(depth.size, uint64_t(kWidth) * kHeight * 4);  // D32
    EXPECT_EQ(color_again.size, color.size);
    for (const auto* memory : {&color, &depth, &color_again}) EXPECT_EQ(close(memory->fd), 0);
}

// The "mesh drawn" semaphore where the device exports semaphores (NVIDIA): new descriptors
// of one semaphore; where it cannot (lavapipe), an error that names the extension. Either way
// a composite told to wait for a semaphore never exported is refused instead of hanging.
TEST_F(Interop, MeshDrawnSemaphoreIsExportedWhereTheDeviceCan) {
    OPEN3D_REQUIRE_DATA(kScene);
    auto backend = PlaybotBackend();
    const bool can = Context().SupportsExternalSemaphoreFd();
    EXPECT_EQ(vulkan::QueryInteropSupport(*backend).external_semaphore_fd, can);
    InteropTargets targets(*backend, kWidth, kHeight);
    InteropCompositeRequest request;
    request.wait_mesh_drawn = true;
    InteropFrame frame;
    ExpectErrorContaining([&] { RenderCompositeToInterop(*backend, targets, request, frame); },
                          "never exported");
    if (!can) {
        ExpectErrorContaining([&] { targets.ExportMeshDrawnSemaphore(); },
                              "cannot export semaphores (VK_KHR_external_semaphore_fd");
        return;
    }
    const int a = targets.ExportMeshDrawnSemaphore();
    const int b = targets.ExportMeshDrawnSemaphore();
    ASSERT_GE(a, 0);
    ASSERT_GE(b, 0);
    EXPECT_NE(a, b);
    EXPECT_EQ(close(a), 0);
    EXPECT_EQ(close(b), 0);
}

TEST_F(Interop, CompositeEqualsTheReadbackPathWithinHalfPrecision) {
    OPEN3D_REQUIRE_DATA(kScene);
    auto backend = PlaybotBackend();
    RenderOutput headless;
    backend->RenderCompositeStage(headless);
    InteropTargets targets(*backend, kWidth, kHeight);
    InteropCompositeRequest request;
    request.read_color = true;
    InteropFrame frame;
    vulkan::RenderCompositeToInterop(*backend, targets, request, frame);
    const HalfComparison c = CompareHalf(frame.color, headless.color);
    EXPECT_TRUE(c.within_bound) << "largest relative error " << c.max_relative;
    EXPECT_GT(c.max_relative, 0.0);  // it is the half image
    EXPECT_EQ(frame.stats.num_tile_entries, headless.stats.num_tile_entries);
    EXPECT_GT(frame.stats.num_tile_entries, 0);
    EXPECT_GT(frame.stats.gpu_composite_ms, 0.0);
    EXPECT_TRUE(frame.linear_depth.IsEmpty());  // not requested
    EXPECT_EQ(backend->GetCounters().composites, 2);
    EXPECT_EQ(backend->GetCounters().composite_reuses, 0);

    // The same request for another view: the recording (which names no camera) is submitted
    // again and must composite that view's entries, as the readback path does.
    const camera::PinholeCamera view8 = camera::ReadCamerasJson(DataPath("playbot/cameras.json"))
                                            .at(8)
                                            .camera.Resized(kWidth, kHeight);
    backend->RenderGeometryStage(view8, config_);
    InteropFrame again;
    vulkan::RenderCompositeToInterop(*backend, targets, request, again);
    EXPECT_EQ(backend->GetCounters().composite_reuses, 1);
    EXPECT_EQ(backend->GetCounters().composites, 3);
    RenderOutput headless8;
    backend->RenderCompositeStage(headless8);
    EXPECT_TRUE(CompareHalf(again.color, headless8.color).within_bound);
    ASSERT_EQ(again.color.NumPixels(), frame.color.NumPixels());
    EXPECT_NE(std::memcmp(again.color.Data<float>(), frame.color.Data<float>(),
                          size_t(frame.color.NumPixels()) * 4 * sizeof(float)),
              0);
    backend->RenderGeometryStage(camera_, config_);
    // Another request (depth read back too) is recorded anew.
    InteropCompositeRequest with_depth = request;
    with_depth.read_depth = true;
    InteropFrame depth_frame;
    vulkan::RenderCompositeToInterop(*backend, targets, with_depth, depth_frame);
    EXPECT_EQ(backend->GetCounters().composite_reuses, 1);
    EXPECT_FALSE(depth_frame.linear_depth.IsEmpty());

    // The overlay is premultiplied on black whatever the config's background: Filament
    // draws the background. Same geometry stage (the background does not change it).
    config_.background = Eigen::Vector3d(0.25, 0.5, 0.75);
    backend->RenderGeometryStage(camera_, config_);
    InteropFrame with_background;
    vulkan::RenderCompositeToInterop(*backend, targets, request, with_background);
    EXPECT_TRUE(with_background.color == frame.color);

    // Sizes must match the camera.
    InteropTargets wrong_size(*backend, kWidth / 2, kHeight);
    EXPECT_THROW(vulkan::RenderCompositeToInterop(*backend, wrong_size, request, frame),
                 core::Open3DError);
}

TEST_F(Interop, EverythingCulledClearsTheColourAndStillMergesDepth) {
    auto backend = MakeBackend();
    backend->SetScene(CreateDefaultGaussianSplatScene());
    camera::LookAtCamera away;
    away.eye = Eigen::Vector3d(0, 0, 50);
    away.center = Eigen::Vector3d(0, 0, 100);  // looking away from the scene
    backend->RenderGeometryStage(camera::PinholeCamera::FromLookAt(away, kWidth, kHeight), {});
    InteropTargets targets(*backend, kWidth, kHeight);
    const float near = 0.1f;
    const t::geometry::Image wall = Wall(5.0f);
    targets.UploadDepth(ToReversedZ(wall, near).data());
    InteropCompositeRequest request;
    request.read_color = true;
    request.read_depth = true;
    request.use_scene_depth = true;
    request.scene_near = near;
    request.depth_near = 1.0f;
    request.depth_far = 9.0f;
    InteropFrame frame;
    vulkan::RenderCompositeToInterop(*backend, targets, request, frame);
    EXPECT_EQ(frame.stats.num_tile_entries, 0);
    EXPECT_EQ(backend->GetCounters().skipped_composites, 1);
    EXPECT_EQ(frame.stats.gpu_composite_ms, 0.0);
    for (int64_t i = 0; i < frame.color.AsTensor().NumElements(); ++i) {
        ASSERT_EQ(frame.color.Data<float>()[i], 0.0f) << i;
    }
    // Merged = the scene depth (the wall, through near / (near / z): within 2 ulp).
    const uint16_t wall_normalized = uint16_t(std::lround((5.0 - 1.0) / 8.0 * 65535.0));
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            const float z = wall.At<float>(y, x);
            ASSERT_NEAR(frame.linear_depth.At<float>(y, x), z, 2e-6f * z) << x << ", " << y;
            ASSERT_EQ(frame.normalized_depth.At<uint16_t>(y, x), z > 0 ? wall_normalized : 65535)
                << x << ", " << y;
        }
    }
}

TEST_F(Interop, SharedDepthOccludesLikeTheReadbackPathsSceneDepth) {
    OPEN3D_REQUIRE_DATA(kScene);
    auto backend = PlaybotBackend();
    RenderOutput plain;
    backend->RenderCompositeStage(plain);
    const t::geometry::Image wall = Wall(MeanDepth(plain));
    CompositeInputs inputs;
    inputs.scene_depth = &wall;
    RenderOutput headless;
    backend->RenderCompositeStage(headless, inputs);

    // Another near plane than the headless path's (config 0.2): the composite must use the
    // request's to convert d back to z.
    InteropTargets targets(*backend, kWidth, kHeight);
    const float near = 0.05f;
    targets.UploadDepth(ToReversedZ(wall, near).data());
    InteropCompositeRequest request;
    request.read_color = true;
    request.use_scene_depth = true;
    request.scene_near = near;
    InteropFrame frame;
    vulkan::RenderCompositeToInterop(*backend, targets, request, frame);
    const HalfComparison c = CompareHalf(frame.color, headless.color);
    EXPECT_TRUE(c.within_bound) << "largest relative error " << c.max_relative;
    // The wall matters: the unoccluded image is far from it.
    EXPECT_FALSE(CompareHalf(plain.color, headless.color).within_bound);

    // Without use_scene_depth the shared depth is ignored.
    request.use_scene_depth = false;
    InteropFrame ignored;
    vulkan::RenderCompositeToInterop(*backend, targets, request, ignored);
    EXPECT_TRUE(CompareHalf(ignored.color, plain.color).within_bound);
}

TEST_F(Interop, ReadDepthMergesSplatAndSceneDepth) {
    OPEN3D_REQUIRE_DATA(kScene);
    auto backend = PlaybotBackend();
    RenderOutput plain;
    backend->RenderCompositeStage(plain);
    const t::geometry::Image wall = Wall(MeanDepth(plain));
    CompositeInputs inputs;
    inputs.scene_depth = &wall;
    RenderOutput headless;  // its depth and alpha are what the merge reads
    backend->RenderCompositeStage(headless, inputs);

    InteropTargets targets(*backend, kWidth, kHeight);
    // The headless path's near plane: the same d reaches the shader, so the composite's
    // depth and alpha images equal the headless ones bit for bit.
    const float near = static_cast<float>(config_.near_plane);
    targets.UploadDepth(ToReversedZ(wall, near).data());
    InteropCompositeRequest request;
    request.read_depth = true;
    request.use_scene_depth = true;
    request.scene_near = near;
    request.depth_near = 0.5f;
    request.depth_far = 4.0f;
    InteropFrame frame;
    vulkan::RenderCompositeToInterop(*backend, targets, request, frame);
    ASSERT_EQ(frame.normalized_depth.GetDtype(), core::Dtype::UInt16);
    EXPECT_TRUE(frame.color.IsEmpty());  // not requested
    EXPECT_GT(frame.stats.gpu_merge_ms, 0.0);
    int splat_wins = 0, wall_wins = 0, nothing = 0;
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            const float alpha = headless.color.At<float>(y, x, 3);
            const float splat =
                alpha > 0.0f && alpha >= 0.5f ? headless.depth_expected.At<float>(y, x) : INFINITY;
            const float scene = wall.At<float>(y, x) > 0.0f ? wall.At<float>(y, x) : INFINITY;
            const float expected = std::min(splat, scene);
            const float merged = frame.linear_depth.At<float>(y, x);
            const uint16_t normalized = frame.normalized_depth.At<uint16_t>(y, x);
            if (std::isinf(expected)) {
                ASSERT_EQ(merged, 0.0f) << x << ", " << y;
                ASSERT_EQ(normalized, 65535) << x << ", " << y;
                ++nothing;
                continue;
            }
            // The wall goes through near / (near / z) on the GPU: within 2 ulp.
            ASSERT_NEAR(merged, expected, 2e-6f * expected) << x << ", " << y;
            (splat <= scene ? splat_wins : wall_wins)++;
            // As the shader computes it, in float; its division need not be correctly
            // rounded (Vulkan: 2.5 ulp), which can only matter next to a .5 tie.
            const float u = std::clamp((merged - 0.5f) / 3.5f, 0.0f, 1.0f) * 65535.0f;
            const bool near_tie = std::abs(u - std::floor(u) - 0.5f) < 0.02f;
            ASSERT_LE(std::abs(float(normalized) - std::round(u)), near_tie ? 1.0f : 0.0f)
                << x << ", " << y << ": " << u;
        }
    }
    // Every case occurs.
    EXPECT_GT(splat_wins, 0);
    EXPECT_GT(wall_wins, 0);
    EXPECT_GT(nothing, 0);
}

TEST_F(Interop, RepeatedCompositesAreIdentical) {
    OPEN3D_REQUIRE_DATA(kScene);
    auto backend = PlaybotBackend();
    InteropTargets targets(*backend, kWidth, kHeight);
    targets.UploadDepth(ToReversedZ(Wall(2.0f), 0.1f).data());
    InteropCompositeRequest request;
    request.read_color = true;
    request.read_depth = true;
    request.use_scene_depth = true;
    request.scene_near = 0.1f;
    InteropFrame first;
    vulkan::RenderCompositeToInterop(*backend, targets, request, first);
    for (int i = 1; i < 50; ++i) {
        InteropFrame frame;
        vulkan::RenderCompositeToInterop(*backend, targets, request, frame);
        ASSERT_TRUE(frame.color == first.color) << "frame " << i;
        ASSERT_TRUE(frame.linear_depth == first.linear_depth) << "frame " << i;
        ASSERT_TRUE(frame.normalized_depth == first.normalized_depth) << "frame " << i;
    }
    EXPECT_EQ(backend->GetCounters().composites, 50);
    EXPECT_EQ(backend->GetCounters().geometry_runs, 1);
}

TEST_F(Interop, EntryBuffersGrowAsInTheReadbackPath) {
    // Room for 1,000 entries; the default scene at 80x60 needs ~15,000 (VulkanBackendTest).
    const t::geometry::PointCloud cloud = CreateDefaultGaussianSplatScene();
    const camera::PinholeCamera cam = GetDefaultSceneCamera().Resized(80, 60);
    auto small = MakeBackend(1000);
    small->SetScene(cloud);
    small->RenderGeometryStage(cam, {});
    InteropTargets targets(*small, 80, 60);
    InteropCompositeRequest request;
    request.read_color = true;
    InteropFrame grown;
    vulkan::RenderCompositeToInterop(*small, targets, request, grown);
    EXPECT_EQ(small->GetCounters().capacity_growths, 1);
    EXPECT_EQ(grown.stats.error_flags, 0u);
    auto ample = MakeBackend();
    ample->SetScene(cloud);
    const RenderOutput reference = ample->Render(cam, {});
    EXPECT_EQ(grown.stats.num_tile_entries, reference.stats.num_tile_entries);
    EXPECT_TRUE(CompareHalf(grown.color, reference.color).within_bound);
}

// The interop composite is submitted behind its geometry stage once the last counters left
// the buffers a quarter free, and reads this frame's counters only after the composite: a
// frame whose entries then outgrew the buffers (the camera zoomed in) is rendered again with
// room, so it still equals the readback path's frame.
TEST_F(Interop, ACompositeBehindItsGeometryStageThatOverflowsIsRenderedAgain) {
    const t::geometry::PointCloud cloud = CreateDefaultGaussianSplatScene();
    const camera::PinholeCamera near = GetDefaultSceneCamera().Resized(320, 240);
    camera::PinholeCamera far = near;
    far.fx *= 0.25;  // the splats cover a sixteenth of the area: far fewer tile entries
    far.fy *= 0.25;
    auto ample = MakeBackend();
    ample->SetScene(cloud);
    const RenderOutput far_reference = ample->Render(far, {});
    const RenderOutput near_reference = ample->Render(near, {});
    const uint32_t capacity = static_cast<uint32_t>(far_reference.stats.num_tile_entries * 2);
    ASSERT_LT(uint64_t(capacity), near_reference.stats.num_tile_entries);

    auto small = MakeBackend(capacity);
    small->SetScene(cloud);
    InteropTargets targets(*small, 320, 240);
    InteropCompositeRequest request;
    request.read_color = true;
    InteropFrame first;
    small->RenderGeometryStage(far, {});
    vulkan::RenderCompositeToInterop(*small, targets, request, first);
    EXPECT_TRUE(CompareHalf(first.color, far_reference.color).within_bound);
    EXPECT_EQ(small->GetCounters().capacity_growths, 0);

    InteropFrame second;
    small->RenderGeometryStage(near, {});
    vulkan::RenderCompositeToInterop(*small, targets, request, second);
    EXPECT_EQ(small->GetCounters().capacity_growths, 1);
    // Behind the geometry stage, then again with room.
    EXPECT_EQ(small->GetCounters().composites, 3);
    EXPECT_EQ(second.stats.error_flags, 0u);
    EXPECT_EQ(second.stats.num_tile_entries, near_reference.stats.num_tile_entries);
    EXPECT_TRUE(CompareHalf(second.color, near_reference.color).within_bound);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
