// Picking a pixel (cpu/Picking.h): the dominant splat by blend weight, worked out by hand for two
// stacked splats, and the picked point on the pixel's ray at the depth the composite's expected
// depth image holds there.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "SplatTestScene.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Composite.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Picking.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"

namespace open3d {
namespace tests {
namespace {

namespace cpu = visualization::rendering::cpu;
using visualization::rendering::RenderConfig;

// A at z = 5 in front of B at z = 6, both on the axis (pixel (32, 32)), scale 0.3 (sigma 6 and
// 5 px: at the centre pixel alpha is the opacity to within 1e-3).
t::geometry::PointCloud TwoStacked(double front_opacity, double back_opacity) {
    std::vector<TestSplat> splats(2);
    splats[0].position = {0, 0, 5};
    splats[0].scale = {0.3, 0.3, 0.3};
    splats[0].opacity = front_opacity;
    splats[1].position = {0, 0, 6};
    splats[1].scale = {0.3, 0.3, 0.3};
    splats[1].opacity = back_opacity;
    return MakeCloud(splats);
}

TEST(Picking, TheSplatOfLargestWeightWins) {
    const RenderConfig config;
    // Front 0.6, back 0.9: weights 0.6 and 0.9 x 0.4 = 0.36, the front wins.
    cpu::PickResult pick = cpu::PickPixel(TwoStacked(0.6, 0.9), MakeTestCamera(), config, 32, 32);
    ASSERT_TRUE(pick.hit);
    EXPECT_EQ(pick.splat, 0);
    EXPECT_NEAR(pick.weight, 0.6, 2e-3);
    EXPECT_NEAR(pick.alpha, 1.0 - 0.4 * 0.1, 2e-3);
    // Front 0.3, back 0.9: weights 0.3 and 0.9 x 0.7 = 0.63, the back wins.
    pick = cpu::PickPixel(TwoStacked(0.3, 0.9), MakeTestCamera(), config, 32, 32);
    EXPECT_EQ(pick.splat, 1);
    EXPECT_NEAR(pick.weight, 0.63, 2e-3);
    // The median: the front alone brings 1 - T to 0.6 >= 0.5 in the first case; in the
    // second only the back does (0.3 + 0.63).
    EXPECT_DOUBLE_EQ(
        cpu::PickPixel(TwoStacked(0.6, 0.9), MakeTestCamera(), config, 32, 32).median_depth, 5.0);
    EXPECT_DOUBLE_EQ(pick.median_depth, 6.0);
}

TEST(Picking, ThePointLiesOnTheRayAtTheCompositesDepth) {
    const RenderConfig config;
    const t::geometry::PointCloud cloud = TwoStacked(0.5, 0.8);
    camera::PinholeCamera cam = MakeTestCamera();
    // A camera moved and turned, so the point's world transform is exercised.
    cam.world_to_camera.topLeftCorner<3, 3>() =
        Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix();
    cam.world_to_camera.topRightCorner<3, 1>() = Eigen::Vector3d(0.1, -0.05, 0.2);
    visualization::rendering::RenderOutput out;
    const std::vector<cpu::ProjectedSplat> splats = cpu::ProjectSplats(cloud, cam, config);
    const cpu::TileLists lists =
        cpu::BuildTileLists(splats, cpu::TileGrid::ForImage(cam.width, cam.height), config);
    cpu::CompositeTiles(splats, lists, cam.width, cam.height, config, {}, out);
    for (const auto& [x, y] : std::vector<std::pair<int, int>>{{30, 33}, {35, 29}, {33, 33}}) {
        SCOPED_TRACE(testing::Message() << "pixel " << x << ", " << y);
        const cpu::PickResult pick = cpu::PickPixel(cloud, cam, config, x, y);
        ASSERT_TRUE(pick.hit);
        // The depth image stores the same quotient rounded to float32.
        const float stored = out.depth_expected.Data<float>()[y * cam.width + x];
        EXPECT_EQ(static_cast<float>(pick.expected_depth), stored);
        EXPECT_NEAR(pick.alpha, out.color.Data<float>()[(y * cam.width + x) * 4 + 3], 1e-6);
        // Back to the camera: view z is the depth, and it projects onto the pixel.
        const Eigen::Vector3d view = cam.GetRotation() * pick.point + cam.GetTranslation();
        EXPECT_NEAR(view.z(), pick.expected_depth, 1e-12);
        EXPECT_NEAR(cam.fx * view.x() / view.z() + cam.cx, x, 1e-9);
        EXPECT_NEAR(cam.fy * view.y() / view.z() + cam.cy, y, 1e-9);
    }
}

TEST(Picking, TheIdImageHoldsEveryPixelsPick) {
    // The composite's ID image (RenderOutput::splat_id) and PickPixel walk the same blend;
    // 60 overlapping splats of random size, depth and opacity make most pixels a contest.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<TestSplat> splats(60);
    for (TestSplat& s : splats) {
        s.position = {u(rng) - 0.5, u(rng) - 0.5, 4.0 + 2.0 * u(rng)};
        s.scale = {0.03 + 0.15 * u(rng), 0.03 + 0.15 * u(rng), 0.1};
        s.opacity = 0.1 + 0.85 * u(rng);
    }
    const t::geometry::PointCloud cloud = MakeCloud(splats);
    const camera::PinholeCamera cam = MakeTestCamera();
    const RenderConfig config;
    cpu::CpuBackend backend;
    backend.SetScene(cloud);
    visualization::rendering::CompositeInputs inputs;
    inputs.splat_id = true;
    const visualization::rendering::RenderOutput out = backend.Render(cam, config, inputs);
    ASSERT_EQ(out.splat_id.GetDtype(), core::Dtype::Int32);
    ASSERT_EQ(out.splat_id.GetRows(), cam.height);
    int hits = 0;
    for (int y = 0; y < cam.height; ++y) {
        for (int x = 0; x < cam.width; ++x) {
            const cpu::PickResult pick = cpu::PickPixel(cloud, cam, config, x, y);
            ASSERT_EQ(out.splat_id.Data<int32_t>()[y * cam.width + x], pick.splat)
                << "pixel " << x << ", " << y;
            hits += pick.hit;
        }
    }
    // Both outcomes occur: covered pixels and the background in the corners.
    EXPECT_GT(hits, 1000);
    EXPECT_LT(hits, cam.width * cam.height);
    // Not asked for: no image.
    EXPECT_TRUE(backend.Render(cam, config, {}).splat_id.IsEmpty());
}

TEST(Picking, AnEmptyPixelMissesAndOneOutsideIsRefused) {
    const RenderConfig config;
    const t::geometry::PointCloud cloud = TwoStacked(0.5, 0.5);
    EXPECT_FALSE(cpu::PickPixel(cloud, MakeTestCamera(), config, 0, 0).hit);
    EXPECT_THROW(cpu::PickPixel(cloud, MakeTestCamera(), config, 64, 0), core::Open3DError);
    EXPECT_THROW(cpu::PickPixel(cloud, MakeTestCamera(), config, 0, -1), core::Open3DError);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
