// Depth-aware compositing through Filament: a red sphere in front of a wall of splats hides
// them exactly where it covers it, splats in front of it stay visible, and with the sphere
// hidden the splats come back and no depth is read.
#include <gtest/gtest.h>

#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using rendering::FrameRequest;
using rendering::FrameResult;
using rendering::SplatSharing;

class OcclusionTest : public FilamentTest, public ::testing::WithParamInterface<SplatSharing> {};

const Eigen::Vector3d kWallColor(0.1, 0.2, 0.9);
const Eigen::Vector3d kFrontColor(0.1, 0.9, 0.2);

TEST_P(OcclusionTest, SphereHidesExactlyTheSplatsBehindIt) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(64, 48);
    const t::geometry::PointCloud wall = MakeSplatWall(4.0, 3.0, 24, kWallColor);
    // A blob in front of the sphere's right half (x = 0.25 at z = 1.2 projects inside it).
    const t::geometry::PointCloud front = MakeSplatBlob(0.2, 0.0, 1.2, 0.08, kFrontColor);

    // Where the sphere is: a mesh-only depth render, compared with the ray-traced sphere.
    rendering::FilamentScene& mesh_only = MakeScene();
    AddRedSphere(mesh_only);
    rendering::FilamentView& view = MakeView(camera, GetParam());
    FrameRequest depth_request;
    depth_request.read_depth = true;
    const FrameResult mesh_depth = renderer_->Draw(mesh_only, view, depth_request);
    EXPECT_FALSE(mesh_depth.splats_drawn);
    const float* sphere_z = mesh_depth.linear_depth.Data<float>();

    rendering::FilamentScene& scene = MakeScene();
    scene.AddGeometry("wall", wall);
    scene.AddGeometry("front", front);
    AddRedSphere(scene);
    FrameRequest request;
    request.read_color = true;
    request.read_depth = true;
    const FrameResult frame = renderer_->Draw(scene, view, request);
    EXPECT_TRUE(frame.splats_drawn);
    EXPECT_TRUE(frame.scene_depth_used);
    EXPECT_EQ(view.GetSplatTargets()->IsZeroCopy(), GetParam() == SplatSharing::kZeroCopy);

    // Without the sphere, from the headless renderer (the splat colour behind and around it).
    const rendering::RenderOutput wall_only = RenderHeadless(wall, camera);
    const rendering::RenderOutput front_only = RenderHeadless(front, camera);
    const uint8_t* rgba = frame.color.Data<uint8_t>();
    const Eigen::Vector4f background = view.GetBackground();
    int sphere_pixels = 0, front_pixels = 0, wall_pixels = 0;
    for (int64_t i = 0; i < camera.width * camera.height; ++i) {
        const int u = int(i % camera.width), v = int(i / camera.width);
        double cos_incidence = 0.0;
        const double ray_z = SphereDepthAt(camera, u, v, &cos_incidence);
        if (ray_z > 0 && SphereDepthTolerance(cos_incidence) > 0) {
            EXPECT_NEAR(sphere_z[i], ray_z, SphereDepthTolerance(cos_incidence))
                << "pixel " << u << "," << v;
        }
        const float front_alpha = front_only.color.Data<float>()[4 * i + 3];
        if (sphere_z[i] > 0 && front_alpha == 0.0f) {
            // Covered by the sphere and nothing in front: exactly the sphere's red.
            EXPECT_EQ(rgba[4 * i + 0], 255) << "pixel " << u << "," << v;
            EXPECT_EQ(rgba[4 * i + 1], 0) << "pixel " << u << "," << v;
            EXPECT_EQ(rgba[4 * i + 2], 0) << "pixel " << u << "," << v;
            ++sphere_pixels;
        } else if (sphere_z[i] > 0 && front_alpha > 0.5f) {
            // The blob in front stays visible: green over red, and its depth wins.
            EXPECT_GT(rgba[4 * i + 1], 100) << "pixel " << u << "," << v;
            EXPECT_NEAR(frame.linear_depth.Data<float>()[i], 1.2, 0.02);
            ++front_pixels;
        } else if (sphere_z[i] == 0 && front_alpha == 0.0f) {
            // Uncovered: the wall as the headless renderer draws it, over the background.
            // 1 LSB: the zero-copy colour is stored as RGBA16F (relative error <= 2^-10).
            const std::array<int, 4> want =
                ExpectedOver(wall_only.color.Data<float>() + 4 * i, background);
            for (int c = 0; c < 4; ++c) {
                EXPECT_NEAR(rgba[4 * i + c], want[c], 1) << "pixel " << u << "," << v;
            }
            ++wall_pixels;
        }
    }
    EXPECT_GT(sphere_pixels, 100);
    EXPECT_GT(front_pixels, 5);
    EXPECT_GT(wall_pixels, 1000);

    // Sphere hidden: the splats behind reappear and the composite reads no depth.
    scene.ShowGeometry("sphere", false);
    const FrameResult hidden = renderer_->Draw(scene, view, request);
    EXPECT_FALSE(hidden.scene_depth_used);
    const int cx = camera.width / 2, cy = camera.height / 2;
    const size_t center = size_t(cy) * camera.width + cx;
    EXPECT_LT(hidden.color.Data<uint8_t>()[4 * center + 0], 100);
    EXPECT_GT(hidden.color.Data<uint8_t>()[4 * center + 2], 150);
    EXPECT_NEAR(hidden.linear_depth.Data<float>()[center], 4.0, 0.05);
}

INSTANTIATE_TEST_SUITE_P(Sharing, OcclusionTest,
                         ::testing::Values(SplatSharing::kZeroCopy, SplatSharing::kHostCopy),
                         SharingTestName);

}  // namespace
}  // namespace tests
}  // namespace open3d
