// The whole Vulkan renderer ("vulkan" backend: geometry stage + composite stage + readback) against
// the CPU reference on real scenes and analytic cases, and the skips it promises (geometry stage
// reuse). Runs on the fixture's device through borrowed handles, so the fixture's
// validation check covers it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStage.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/RadixSort.h"
#include "visualization/rendering/gaussian_splat/vulkan/SharedScenes.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
using vulkan::GaussianSplatVulkanBackend;

using VulkanBackend = VulkanTest;

TEST_F(VulkanBackend, RealScenesMatchTheReference) {
    // Issue 9's accuracy targets at CI sizes. Measured on lavapipe (and the same binary on an
    // H100): PSNR 103-124 dB, max abs error <= 2.3e-3, 0-0.02% of elements over 1/255 (a
    // near-tie in depth order flips two splats at a few pixels), p99.9 <= 1e-6.
    auto backend = MakeBackend();
    for (const SharedSceneFiles& c : kSharedScenes) {
        OPEN3D_REQUIRE_DATA(c.scene);
        const auto [cloud, views] = ReadSharedScene(c);
        backend->SetScene(cloud);
        for (const auto& [view, w, h] : kSharedSceneViews) {
            const camera::PinholeCamera cam = views.at(view).camera.Resized(w, h);
            const RenderOutput gpu = backend->Render(cam, {});
            const RenderOutput ref = cpu::RenderReference(cloud, cam, {});
            const auto m =
                t::geometry::ComputeImageErrorMetrics(gpu.color, ref.color, 1.0, 1.0 / 255.0);
            SCOPED_TRACE(std::string(c.scene) + " view " + std::to_string(view));
            EXPECT_GE(m.psnr_db, 80.0);
            EXPECT_LE(m.fraction_over_threshold, 1e-4 * 4);  // 4 channels per pixel
            EXPECT_LE(t::geometry::ComputeAbsErrorPercentile(gpu.color, ref.color, 0.999),
                      0.1 / 255.0);
            EXPECT_EQ(gpu.stats.error_flags, 0u);
            // Depth: alpha-weighted view z where the pixel is covered.
            const auto d = t::geometry::ComputeImageErrorMetrics(gpu.depth_expected,
                                                                 ref.depth_expected, 1.0, 1e-3);
            EXPECT_LE(d.fraction_over_threshold, 5e-3);
        }
    }
}

TEST_F(VulkanBackend, AnOffCentreCropMatchesTheReference) {
    // Pixels [56, 88) x [32, 64) of a 96 x 96 view as a 32 x 32 crop: its principal point
    // lies 8.5 pixels left of its image, which spans X / Z = 8.5 / f .. 40.5 / f, mostly past
    // the 20.8 / f a band centred on the axis would clamp at. The shader must centre its
    // guard band on the image as the reference does (CpuProjection.
    // TheGuardBandFollowsAnOffCentrePrincipalPoint).
    const std::string path = DataPath("playbot/playbot_31k.ply");
    if (!FileExists(path)) OPEN3D_SKIP_OR_FAIL_WHEN_UNAVAILABLE(path + " is absent");
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(path, cloud);
    camera::PinholeCamera crop =
        camera::ReadCamerasJson(DataPath("playbot/cameras.json")).at(0).camera.Resized(96, 96);
    crop.width = crop.height = 32;
    crop.cx -= 56.0;
    crop.cy -= 32.0;
    auto backend = MakeBackend();
    backend->SetScene(cloud);
    const RenderOutput gpu = backend->Render(crop, {});
    const RenderOutput ref = cpu::RenderReference(cloud, crop, {});
    EXPECT_GT(gpu.stats.num_visible, 1000);
    const auto m = t::geometry::ComputeImageErrorMetrics(gpu.color, ref.color, 1.0, 1.0 / 255.0);
    EXPECT_GE(m.psnr_db, 80.0) << "max error " << m.max_abs_error;
    EXPECT_LE(m.max_abs_error, 1.0 / 255.0) << m.psnr_db << " dB";
}

TEST_F(VulkanBackend, UnchangedViewReusesGeometryStageAndGivesTheSameImage) {
    auto backend = MakeBackend();
    const t::geometry::PointCloud cloud = CreateDefaultGaussianSplatScene();
    backend->SetScene(cloud);
    const camera::PinholeCamera cam = GetDefaultSceneCamera().Resized(80, 60);
    const RenderOutput first = RenderStages(*backend, cam, {});
    const RenderOutput second = RenderStages(*backend, cam, {});
    EXPECT_EQ(backend->GetCounters().geometry_runs, 1);
    EXPECT_EQ(backend->GetCounters().geometry_reuses, 1);
    EXPECT_TRUE(second.stats.geometry_reused);
    EXPECT_TRUE(first.color.AsTensor() == second.color.AsTensor());
    // Another view, or reuse switched off, runs the geometry stage again.
    RenderConfig no_reuse;
    no_reuse.reuse_geometry = false;
    RenderStages(*backend, cam, no_reuse);
    RenderStages(*backend, cam.Resized(64, 48), {});
    EXPECT_EQ(backend->GetCounters().geometry_runs, 3);
    EXPECT_EQ(backend->GetCounters().skipped_composites, 0);
}

TEST_F(VulkanBackend, AReusedGeometryStageCompositesOverTheNewBackground) {
    // The background is a composite setting: a frame that reuses the geometry stage must
    // still blend over the background it was given, as the CPU backend does.
    auto backend = MakeBackend();
    backend->SetScene(CreateDefaultGaussianSplatScene());
    const camera::PinholeCamera cam = GetDefaultSceneCamera().Resized(80, 60);
    RenderConfig config;
    config.background = Eigen::Vector3d(0.0, 0.0, 0.0);
    RenderStages(*backend, cam, config);
    config.background = Eigen::Vector3d(1.0, 0.5, 0.25);
    const RenderOutput white = RenderStages(*backend, cam, config);
    ASSERT_TRUE(white.stats.geometry_reused);
    cpu::CpuBackend reference;
    reference.SetScene(CreateDefaultGaussianSplatScene());
    reference.RenderGeometryStage(cam, config);
    RenderOutput want;
    reference.RenderCompositeStage(want, {});
    // The corner pixel lies outside every splat of the default scene: the background alone.
    const float* got = white.color.Data<float>();
    const float* expected = want.color.Data<float>();
    for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(got[c], expected[c]) << "channel " << c;
        EXPECT_EQ(got[c], static_cast<float>(config.background[c])) << "channel " << c;
    }
}

TEST_F(VulkanBackend, DepthImagesAreComputedOnlyWhenAskedFor) {
    // Each depth output is a specialisation of the composite that only drops arithmetic: the
    // colour, and every depth image that is asked for, must equal the full composite's bit for
    // bit; the others come back empty (the CPU reference returns the same shapes).
    const t::geometry::PointCloud cloud = CreateDefaultGaussianSplatScene();
    const camera::PinholeCamera cam = GetDefaultSceneCamera().Resized(72, 40);
    auto backend = MakeBackend();
    backend->SetScene(cloud);
    cpu::CpuBackend reference;
    reference.SetScene(cloud);
    backend->RenderGeometryStage(cam, {});
    RenderOutput full;
    backend->RenderCompositeStage(full, {});
    ASSERT_FALSE(full.depth_expected.IsEmpty());
    ASSERT_FALSE(full.depth_median.IsEmpty());
    // Both depths differ from 0 somewhere, so a missing store would show.
    const auto positive = [](const t::geometry::Image& image) {
        const float* v = image.Data<float>();
        return std::count_if(v, v + image.GetRows() * image.GetCols(),
                             [](float z) { return z > 0.f; });
    };
    EXPECT_GT(positive(full.depth_expected), 100);
    EXPECT_GT(positive(full.depth_median), 100);
    reference.RenderGeometryStage(cam, {});
    camera::LookAtCamera look_away;
    look_away.eye = Eigen::Vector3d(0, 0, 50);
    look_away.center = Eigen::Vector3d(0, 0, 100);
    const camera::PinholeCamera away =
        camera::PinholeCamera::FromLookAt(look_away, cam.width, cam.height);
    for (const auto& [expected, median] :
         {std::pair{false, false}, std::pair{true, false}, std::pair{false, true}}) {
        SCOPED_TRACE("expected " + std::to_string(expected) + " median " + std::to_string(median));
        // An empty view clears every image first, so an image the composite should write but
        // does not would read back as zeros, not as the full composite's values.
        ASSERT_EQ(RenderStages(*backend, away, {}).stats.num_tile_entries, 0);
        backend->RenderGeometryStage(cam, {});
        CompositeInputs inputs;
        inputs.expected_depth = expected;
        inputs.median_depth = median;
        RenderOutput out;
        backend->RenderCompositeStage(out, inputs);
        EXPECT_TRUE(out.color.AsTensor() == full.color.AsTensor());
        EXPECT_EQ(out.depth_expected.IsEmpty(), !expected);
        EXPECT_EQ(out.depth_median.IsEmpty(), !median);
        if (expected) {
            EXPECT_TRUE(out.depth_expected.AsTensor() == full.depth_expected.AsTensor());
        }
        if (median) {
            EXPECT_TRUE(out.depth_median.AsTensor() == full.depth_median.AsTensor());
        }
        RenderOutput ref;
        reference.RenderCompositeStage(ref, inputs);
        EXPECT_EQ(ref.depth_expected.IsEmpty(), !expected);
        EXPECT_EQ(ref.depth_median.IsEmpty(), !median);
    }
}

TEST_F(VulkanBackend, EntryBuffersGrowInsteadOfDroppingEntries) {
    // Start with room for 1,000 entries; the default scene at 80x60 needs ~15,000. The frame
    // must come out complete (no flag), identical to one rendered with ample buffers, on
    // both paths (each keeps its own entry buffers).
    const t::geometry::PointCloud cloud = CreateDefaultGaussianSplatScene();
    const camera::PinholeCamera cam = GetDefaultSceneCamera().Resized(80, 60);
    auto ample = MakeBackend();
    ample->SetScene(cloud);
    const RenderOutput reference = ample->Render(cam, {});
    for (const bool stages : {false, true}) {
        SCOPED_TRACE(stages ? "stage path" : "submission path");
        auto small = MakeBackend(1000);
        small->SetScene(cloud);
        const auto render = [&](const RenderConfig& config) {
            return stages ? RenderStages(*small, cam, config) : small->Render(cam, config);
        };
        const RenderOutput grown = render({});
        EXPECT_EQ(small->GetCounters().capacity_growths, 1);
        EXPECT_EQ(grown.stats.error_flags, 0u);
        EXPECT_GT(grown.stats.num_tile_entries, 1000);
        EXPECT_EQ(grown.stats.num_tile_entries, reference.stats.num_tile_entries);
        EXPECT_TRUE(grown.color.AsTensor() == reference.color.AsTensor());
        // The config limit still binds: entries past it are dropped and flagged, not grown.
        RenderConfig limited;
        limited.max_tile_entries_total = 500;
        EXPECT_NE(render(limited).stats.error_flags & kEntriesDropped, 0u);
        EXPECT_EQ(small->GetCounters().capacity_growths, 1);
    }
}

TEST_F(VulkanBackend, EntryCapacityStopsAtTheSortLimit) {
    // The config's limit binds below the sort's; above it, the device's sort limit does (the
    // scan saturates later), and geometry stage accepts exactly that capacity.
    auto backend = MakeBackend();
    const uint32_t sort_limit = backend->SortMaxCount();
    const vulkan::VulkanDeviceInfo& info = backend->GetContext().GetDeviceInfo();
    EXPECT_EQ(sort_limit, vulkan::RadixSort::MaxCountFor(info.max_storage_buffer_range));
    EXPECT_EQ(backend->MaxSceneSplats(), int64_t(sort_limit));
    RenderConfig config;
    config.max_tile_entries_total = 1000;
    EXPECT_EQ(GaussianSplatVulkanBackend::MaxEntryCapacity(config, sort_limit), 1000u);
    static_assert(vulkan::RadixSort::kMaxCount < shader::kScanSaturation - 1);
    for (uint64_t total : {uint64_t(sort_limit), uint64_t(sort_limit) + 1, uint64_t(1) << 40}) {
        config.max_tile_entries_total = total;
        EXPECT_EQ(GaussianSplatVulkanBackend::MaxEntryCapacity(config, sort_limit), sort_limit);
    }
    const uint32_t bound = vulkan::RadixSort::kMaxCount;
    EXPECT_NO_THROW(vulkan::GaussianGeometryStage::GetStorageRequirements(1000, bound));
    EXPECT_NO_THROW(vulkan::RadixSort::GetStorageRequirements(bound));
    EXPECT_THROW(vulkan::GaussianGeometryStage::GetStorageRequirements(1000, bound + 1),
                 core::Open3DError);
    EXPECT_THROW(vulkan::GaussianGeometryStage::GetStorageRequirements(bound + 1, 1000),
                 core::Open3DError);
}

TEST_F(VulkanBackend, RejectsANearPlaneThatIsNotPositive) {
    // As the CPU backend (BackendTest.cpp): the depth sort orders float bits, which a
    // negative depth kept by a negative near plane would put after every positive one.
    auto backend = MakeBackend();
    backend->SetScene(CreateDefaultGaussianSplatScene());
    for (double near : {-0.5, 0.0, std::nan("")}) {
        RenderConfig config;
        config.near_plane = near;
        EXPECT_THROW(backend->RenderGeometryStage(GetDefaultSceneCamera(), config),
                     core::Open3DError)
            << near;
    }
    EXPECT_EQ(backend->GetCounters().geometry_runs, 0);
}

TEST_F(VulkanBackend, EmptyViewIsBackgroundOnly) {
    auto backend = MakeBackend();
    backend->SetScene(CreateDefaultGaussianSplatScene());
    camera::LookAtCamera away;
    away.eye = Eigen::Vector3d(0, 0, 50);
    away.center = Eigen::Vector3d(0, 0, 100);  // looking away from the scene
    RenderConfig config;
    config.background = Eigen::Vector3d(0.25, 0.5, 0.75);
    const camera::PinholeCamera cam = camera::PinholeCamera::FromLookAt(away, 33, 17);
    const RenderOutput out = RenderStages(*backend, cam, config);
    EXPECT_EQ(out.stats.num_visible, 0);
    EXPECT_EQ(out.stats.num_tile_entries, 0);
    // Nothing to blend: the stage path records no composite dispatch (the sorts dispatch
    // zero workgroups from the GPU counts); the images are cleared instead.
    EXPECT_EQ(backend->GetCounters().skipped_composites, 1);
    EXPECT_EQ(out.stats.gpu_composite_ms, 0.0);
    // The submission path composites zero entries (its recording does not depend on the
    // counts): the same images, bit for bit.
    const RenderOutput submitted = backend->Render(cam, config);
    EXPECT_EQ(submitted.stats.num_tile_entries, 0);
    EXPECT_TRUE(submitted.color.AsTensor() == out.color.AsTensor());
    EXPECT_TRUE(submitted.depth_expected.AsTensor() == out.depth_expected.AsTensor());
    EXPECT_TRUE(submitted.depth_median.AsTensor() == out.depth_median.AsTensor());
    for (int64_t i = 0; i < out.depth_expected.NumPixels(); ++i) {
        ASSERT_EQ(out.depth_expected.Data<float>()[i], 0.0f);
    }
    for (int64_t i = 0; i < out.color.NumPixels(); ++i) {
        ASSERT_EQ(out.color.Data<float>()[i * 4 + 0], 0.25f);
        ASSERT_EQ(out.color.Data<float>()[i * 4 + 2], 0.75f);
        ASSERT_EQ(out.color.Data<float>()[i * 4 + 3], 0.0f);
    }
}

TEST_F(VulkanBackend, SceneDepthOccludesLikeTheReference) {
    auto backend = MakeBackend();
    const t::geometry::PointCloud cloud = CreateDefaultGaussianSplatScene();
    backend->SetScene(cloud);
    const camera::PinholeCamera cam = GetDefaultSceneCamera().Resized(64, 48);
    // A wall at the depth of the scene's middle over the left half of the image.
    const RenderOutput plain = cpu::RenderReference(cloud, cam, {});
    t::geometry::Image wall(48, 64, 1, core::Dtype::Float32);
    double mid = 0;
    int64_t covered = 0;
    for (int64_t i = 0; i < plain.depth_expected.NumPixels(); ++i) {
        if (plain.depth_expected.Data<float>()[i] > 0) {
            mid += plain.depth_expected.Data<float>()[i];
            ++covered;
        }
    }
    ASSERT_GT(covered, 0);
    mid /= covered;
    for (int y = 0; y < 48; ++y) {
        for (int x = 0; x < 64; ++x) wall.At<float>(y, x) = x < 32 ? float(mid) : 0.0f;
    }
    CompositeInputs inputs;
    inputs.scene_depth = &wall;
    backend->RenderGeometryStage(cam, {});
    RenderOutput gpu;
    backend->RenderCompositeStage(gpu, inputs);
    cpu::CpuBackend reference;
    reference.SetScene(cloud);
    reference.RenderGeometryStage(cam, {});
    RenderOutput ref;
    reference.RenderCompositeStage(ref, inputs);
    // The wall is converted to reversed-Z (near / z) and back on the GPU: a splat within
    // float rounding of the wall may flip; measured PSNR 90+ dB.
    EXPECT_GE(t::geometry::ComputePSNR(gpu.color, ref.color, 1.0), 60.0);
    EXPECT_LT(t::geometry::ComputePSNR(gpu.color, plain.color, 1.0), 40.0);  // the wall matters
}

TEST_F(VulkanBackend, CompactStorageStaysWithinItsBudget) {
    OPEN3D_REQUIRE_DATA("playbot/playbot_31k.ply");
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(DataPath("playbot/playbot_31k.ply"), cloud);
    const auto cam =
        camera::ReadCamerasJson(DataPath("playbot/cameras.json")).at(0).camera.Resized(96, 96);
    auto backend = MakeBackend();
    backend->SetScene(cloud);
    RenderConfig compact;
    compact.compact_storage = true;
    const RenderOutput out = backend->Render(cam, compact);
    const RenderOutput ref = cpu::RenderReference(cloud, cam, {});
    // Issue 9: compact >= 55 dB (measured 82-84 dB at 96x96 and 128x128).
    EXPECT_GE(t::geometry::ComputePSNR(out.color, ref.color, 1.0), 55.0);
    EXPECT_LE(static_cast<double>(out.stats.gpu_scene_bytes) / cloud.NumPoints(), 140.0);
    EXPECT_EQ(backend->GetCounters().scene_uploads, 2);  // exact at SetScene, then compact
}

}  // namespace
}  // namespace tests
}  // namespace open3d
