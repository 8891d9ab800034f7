// Views and scenes that do not fit in device memory are refused before anything is
// allocated, with the numbers and a size that fits; that size then renders
// (OPEN3D_DEVICE_MEMORY_LIMIT stands in for a small device); a buffer past one storage
// binding's range is refused too.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStageResources.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace {

namespace rendering = visualization::rendering;
using VulkanMemoryCheck = VulkanTest;

TEST_F(VulkanMemoryCheck, ALargeViewIsRefusedWithASizeThatFits) {
    auto backend = MakeBackend();
    backend->SetScene(rendering::CreateDefaultGaussianSplatScene());
    rendering::RenderConfig config;
    camera::PinholeCamera camera =
        camera::PinholeCamera::FromLookAt(rendering::GetDefaultSceneLookAt(), 4000, 4000);
    // 4000 x 4000 x (52 bytes + the composite state) is more than 800 MB.
    ScopedEnvironment limit("OPEN3D_DEVICE_MEMORY_LIMIT", "400000000");
    std::string message;
    try {
        RenderStages(*backend, camera, config);
    } catch (const core::Open3DError& e) {
        message = e.what();
    }
    // "... a 4000x4000 view needs N MB of device memory for its images, F MB is free; WxH
    // would fit" (parsed by hand: std::regex trips GCC 12's -Wmaybe-uninitialized at -O1).
    const size_t at = message.find("a 4000x4000 view needs ");
    ASSERT_NE(at, std::string::npos) << message;
    double need_mb = 0, free_mb = 0;
    int w = 0, h = 0;
    ASSERT_EQ(std::sscanf(message.c_str() + at,
                          "a 4000x4000 view needs %lf MB of device memory for its images, %lf MB "
                          "is free; %dx%d would fit",
                          &need_mb, &free_mb, &w, &h),
              4)
        << message;
    EXPECT_GT(need_mb, 800.0);
    EXPECT_LT(free_mb, 400.0);
    EXPECT_EQ(w, h);
    EXPECT_GT(w, 1000);
    camera = camera.Resized(w, h);
    const rendering::RenderOutput out = RenderStages(*backend, camera, config);
    EXPECT_EQ(out.color.GetCols(), w);
    EXPECT_GT(out.stats.num_visible, 0);
}

TEST_F(VulkanMemoryCheck, ASceneThatDoesNotFitIsRefused) {
    auto backend = MakeBackend();
    ScopedEnvironment limit("OPEN3D_DEVICE_MEMORY_LIMIT", "1000");
    try {
        backend->SetScene(rendering::CreateDefaultGaussianSplatScene());
        FAIL() << "a scene was uploaded into 1000 bytes";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("of device memory"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("OPEN3D_DEVICE_MEMORY_LIMIT"), std::string::npos)
            << e.what();
    }
}

TEST_F(VulkanMemoryCheck, ABufferPastOneStorageBindingIsRefused) {
    // Per-view buffers are bound whole: projected records of one slot past the device's
    // maxStorageBufferRange (lavapipe 128 MiB: 2.1M slots; the H200 4 GiB: 67M) are refused
    // before that buffer is made; a driver without validation reads zeros past the range.
    const uint64_t limit = Context().GetDeviceInfo().max_storage_buffer_range;
    const uint64_t record = sizeof(visualization::rendering::shader::GaussianProjectedSplat);
    const uint32_t slots = static_cast<uint32_t>(limit / record + 1);
    ASSERT_LE(slots, rendering::vulkan::RadixSort::kMaxCount);
    rendering::vulkan::GeometryStageViewResources view;
    try {
        view.Allocate(Context(), slots, 16);
        FAIL() << "per-view buffers for " << slots << " slots were made";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("maxStorageBufferRange"), std::string::npos)
            << e.what();
    }
    view.Allocate(Context(), static_cast<uint32_t>(limit / record), 16);  // just fits
    EXPECT_TRUE(view);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
