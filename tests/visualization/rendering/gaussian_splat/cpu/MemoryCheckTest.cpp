// The CPU reference refuses an image that does not fit in host memory before it allocates
// it, naming a size that fits; that size then renders (OPEN3D_HOST_MEMORY_LIMIT stands in
// for a small machine: 16384 x 16384 once took 8 GB here).
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "TestUtility.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/DefaultScene.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"

namespace open3d {
namespace tests {
namespace {

namespace rendering = visualization::rendering;

TEST(CpuMemoryCheck, ALargeImageIsRefusedWithASizeThatFits) {
    rendering::cpu::CpuBackend backend;
    backend.SetScene(rendering::CreateDefaultGaussianSplatScene());
    camera::PinholeCamera camera =
        camera::PinholeCamera::FromLookAt(rendering::GetDefaultSceneLookAt(), 4000, 4000);
    // 4000 x 4000 x 24 bytes (RGBA32F and two float depths) = 384 MB.
    ScopedEnvironment limit("OPEN3D_HOST_MEMORY_LIMIT", "20000000");
    std::string message;
    try {
        backend.Render(camera, rendering::RenderConfig{});
    } catch (const core::Open3DError& e) {
        message = e.what();
    }
    // (Parsed by hand: std::regex trips GCC 12's -Wmaybe-uninitialized in the -O1 ASan build.)
    const std::string expected =
        "cpu backend: a 4000x4000 image needs 384.0 MB of memory, 20.0 MB is available "
        "(OPEN3D_HOST_MEMORY_LIMIT); ";
    ASSERT_EQ(message.rfind(expected, 0), 0u) << message;
    int w = 0, h = 0;
    ASSERT_EQ(std::sscanf(message.c_str() + expected.size(), "%dx%d would fit", &w, &h), 2)
        << message;
    EXPECT_EQ(w, h);
    EXPECT_GT(w, 500);  // 4000 * sqrt(20 / 384) * 0.9 = 821
    const rendering::RenderOutput out = backend.Render(camera.Resized(w, h), {});
    EXPECT_EQ(out.color.GetCols(), w);
    EXPECT_GT(out.stats.num_visible, 0);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
