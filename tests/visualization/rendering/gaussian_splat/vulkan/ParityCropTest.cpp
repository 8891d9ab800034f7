// The Vulkan backend against the original 3DGS CUDA rasterizer on the crops around the worst
// pixels of three views (ParityCrops.h), as the CPU reference's parity test does: the default
// depth order must reproduce the original's draw order on the GPU too.
#include <gtest/gtest.h>

#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "visualization/rendering/gaussian_splat/ParityCrops.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;

class VulkanParityCrop : public VulkanTest, public ::testing::WithParamInterface<ParityCrop> {};

TEST_P(VulkanParityCrop, ReproducesTheOriginalRasterizer) {
    const ParityCrop& c = GetParam();
    OPEN3D_REQUIRE_DATA(c.scene);
    OPEN3D_REQUIRE_DATA(std::string("parity/") + c.name + "_ref_crop.npy");
    t::geometry::PointCloud cloud;
    t::io::ReadPointCloud(DataPath(c.scene), cloud);
    vulkan::GaussianSplatVulkanBackend backend(
        vulkan::VulkanContext::CreateFromBorrowed(BorrowedHandles()), 1u << 22);
    backend.SetScene(cloud);
    const RenderOutput out = backend.Render(ParityCamera(c), {});
    const auto m = CompareWithParityCrop(out.color, c);
    EXPECT_GE(m.psnr_db, c.vulkan_min_psnr_db) << c.name << ": max error " << m.max_abs_error;
    EXPECT_LE(m.max_abs_error, 1.0 / 255.0) << c.name << ": PSNR " << m.psnr_db << " dB";
}

INSTANTIATE_TEST_SUITE_P(Views, VulkanParityCrop, ::testing::ValuesIn(kParityCrops),
                         [](const ::testing::TestParamInfo<ParityCrop>& info) {
                             return std::string(info.param.name);
                         });

}  // namespace
}  // namespace tests
}  // namespace open3d
