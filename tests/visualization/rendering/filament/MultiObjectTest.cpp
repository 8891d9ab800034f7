// Several splat clouds in one scene: hiding one removes exactly its pixels with a mask
// update and no rebuild of the merged scene; remove, re-add and update work.
#include <gtest/gtest.h>

#include "open3d/core/Exception.h"
#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using MultiObject = FilamentTest;

// Two blobs side by side that do not overlap on screen.
const Eigen::Vector3d kLeftColor(0.9, 0.2, 0.1), kRightColor(0.1, 0.3, 0.9);

t::geometry::Image Render(rendering::Open3DScene& scene) { return scene.RenderToImage(); }

bool SameImage(const t::geometry::Image& a, const t::geometry::Image& b) {
    return a.NumPixels() == b.NumPixels() &&
           std::equal(a.Data<uint8_t>(), a.Data<uint8_t>() + a.NumPixels() * 3, b.Data<uint8_t>());
}

TEST_F(MultiObject, ShowRemoveAddUpdate) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(64, 32);
    const t::geometry::PointCloud left = MakeSplatBlob(-0.8, 0, 3, 0.3, kLeftColor);
    const t::geometry::PointCloud right = MakeSplatBlob(0.8, 0, 3, 0.3, kRightColor);

    rendering::Open3DScene& only_right = MakeOpen3DScene();
    only_right.AddGeometry("right", right);
    only_right.SetupCamera(camera);
    const t::geometry::Image right_image = Render(only_right);
    rendering::Open3DScene& only_left = MakeOpen3DScene();
    only_left.AddGeometry("left", left);
    only_left.SetupCamera(camera);
    const t::geometry::Image left_image = Render(only_left);

    rendering::Open3DScene& scene = MakeOpen3DScene();
    scene.AddGeometry("left", left);
    scene.AddGeometry("right", right);
    scene.SetupCamera(camera);
    const t::geometry::Image both = Render(scene);
    const auto& counters = scene.GetScene().GetCounters();
    EXPECT_EQ(counters.merged_rebuilds, 1);
    EXPECT_FALSE(SameImage(both, right_image));

    // Hide the left cloud: exactly the right-only picture, by a mask update alone.
    scene.ShowGeometry("left", false);
    EXPECT_TRUE(SameImage(Render(scene), right_image));
    EXPECT_EQ(counters.merged_rebuilds, 1);
    EXPECT_EQ(counters.mask_updates, 1);
    scene.ShowGeometry("left", true);
    EXPECT_TRUE(SameImage(Render(scene), both));
    EXPECT_EQ(counters.merged_rebuilds, 1);
    EXPECT_EQ(counters.mask_updates, 2);

    // Remove and re-add: a rebuild each; the picture comes back.
    EXPECT_TRUE(scene.RemoveGeometry("left"));
    EXPECT_FALSE(scene.RemoveGeometry("left"));
    EXPECT_TRUE(SameImage(Render(scene), right_image));
    scene.AddGeometry("left", left);
    EXPECT_TRUE(SameImage(Render(scene), both));
    EXPECT_EQ(counters.merged_rebuilds, 3);
    EXPECT_THROW(scene.AddGeometry("left", left), core::Open3DError);

    // Update: the right cloud recoloured; with the left one hidden the picture is the
    // new cloud's alone, and the left one's visibility survived the rebuild.
    const t::geometry::PointCloud green =
        MakeSplatBlob(0.8, 0, 3, 0.3, Eigen::Vector3d(0.1, 0.9, 0.2));
    rendering::Open3DScene& only_green = MakeOpen3DScene();
    only_green.AddGeometry("green", green);
    only_green.SetupCamera(camera);
    const t::geometry::Image green_image = Render(only_green);
    scene.ShowGeometry("left", false);
    scene.UpdateGeometry("right", green);
    EXPECT_TRUE(SameImage(Render(scene), green_image));
    EXPECT_FALSE(scene.GetScene().IsGeometryVisible("left"));
    scene.ShowGeometry("left", true);
    scene.RemoveGeometry("right");
    EXPECT_TRUE(SameImage(Render(scene), left_image));
    EXPECT_THROW(scene.ShowGeometry("nothing", true), core::Open3DError);
    EXPECT_THROW(scene.UpdateGeometry("nothing", left), core::Open3DError);

    // Everything removed: no splat stage runs, the background shows.
    scene.ClearGeometry();
    const t::geometry::Image empty = Render(scene);
    EXPECT_FALSE(scene.GetLastFrame().splats_drawn);
    EXPECT_EQ(
        *std::max_element(empty.Data<uint8_t>(), empty.Data<uint8_t>() + empty.NumPixels() * 3), 0);
}

TEST_F(MultiObject, CpuBackendWithoutMaskRebuildsVisibleClouds) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(32, 16);
    rendering::Open3DSceneOptions cpu;
    cpu.backend = "cpu";
    rendering::Open3DScene& scene = MakeOpen3DScene(cpu);
    scene.AddGeometry("left", MakeSplatBlob(-0.8, 0, 3, 0.3, kLeftColor));
    scene.AddGeometry("right", MakeSplatBlob(0.8, 0, 3, 0.3, kRightColor));
    scene.SetupCamera(camera);
    Render(scene);
    EXPECT_FALSE(scene.GetView().GetSplatTargets()->IsZeroCopy());
    scene.ShowGeometry("left", false);
    const t::geometry::Image hidden = Render(scene);
    // The CPU reference has no mask: the hidden cloud is left out of a rebuilt scene.
    EXPECT_EQ(scene.GetScene().GetCounters().merged_rebuilds, 2);
    const uint8_t* px = hidden.Data<uint8_t>();
    EXPECT_EQ(px[3 * (8 * 32 + 8)], 0);         // where the left blob was
    EXPECT_GT(px[3 * (8 * 32 + 23) + 2], 100);  // the right blob
}

}  // namespace
}  // namespace tests
}  // namespace open3d
