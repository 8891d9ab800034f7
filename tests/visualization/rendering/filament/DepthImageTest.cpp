// RenderToDepthImage: the merged depth is the sphere's where the sphere is in front, the
// splats' where they cover the pixel, and the far value where nothing is.
#include <gtest/gtest.h>

#include <cmath>

#include "open3d/core/Exception.h"
#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using DepthImage = FilamentTest;

TEST_F(DepthImage, MergesSphereAndSplatDepth) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(64, 48);
    // A wall of splats on the left only (x < 0), so the right edge shows nothing.
    const t::geometry::PointCloud wall = MakeSplatWall(4.0, 0.8, 10, Eigen::Vector3d(0, 0, 1));
    t::geometry::PointCloud shifted = wall;
    shifted.Translate(Eigen::Vector3d(-1.2, 0, 0));
    rendering::Open3DScene& scene = MakeOpen3DScene();
    scene.AddGeometry("wall", shifted);
    AddRedSphere(scene.GetScene());
    scene.SetupCamera(camera);
    const float near = 0.5f, far = 10.0f;
    const t::geometry::Image z = scene.RenderToDepthImage(rendering::DepthFormat::kViewZ);
    const t::geometry::Image u =
        scene.RenderToDepthImage(rendering::DepthFormat::kNormalized16, near, far);
    ASSERT_EQ(z.GetDtype(), core::Dtype::Float32);
    ASSERT_EQ(u.GetDtype(), core::Dtype::UInt16);
    EXPECT_TRUE(scene.GetLastFrame().scene_depth_used);
    const rendering::RenderOutput splats = RenderHeadless(shifted, camera);

    int sphere = 0, splat = 0, empty = 0;
    for (int64_t i = 0; i < z.NumPixels(); ++i) {
        const int px = int(i % camera.width), py = int(i / camera.width);
        double cos_incidence = 0.0;
        const double sphere_z = SphereDepthAt(camera, px, py, &cos_incidence);
        const float alpha = splats.color.Data<float>()[4 * i + 3];
        const float zi = z.Data<float>()[i];
        const uint16_t ui = u.Data<uint16_t>()[i];
        if (sphere_z > 0 && SphereDepthTolerance(cos_incidence) > 0) {
            // The sphere (z <= 2) is in front of every splat (z = 4).
            EXPECT_NEAR(zi, sphere_z, SphereDepthTolerance(cos_incidence)) << px << "," << py;
            ++sphere;
        } else if (sphere_z == 0 && alpha >= 0.5f) {
            // The splats' expected depth; 1e-5 relative: float32 sums in another order.
            EXPECT_NEAR(zi, splats.depth_expected.Data<float>()[i], 4e-5) << px << "," << py;
            ++splat;
        } else if (sphere_z == 0 && alpha == 0.0f) {
            EXPECT_EQ(zi, 0.0f) << px << "," << py;
            EXPECT_EQ(ui, 65535) << px << "," << py;
            ++empty;
            continue;
        } else {
            continue;  // silhouette or thin splat coverage: either may win
        }
        // Normalised: round(65535 (z - near) / (far - near)); 1 LSB for the GPU's division.
        const double want = std::round(65535.0 * (zi - near) / (far - near));
        EXPECT_NEAR(ui, want, 1.0) << px << "," << py;
    }
    EXPECT_GT(sphere, 100);
    EXPECT_GT(splat, 100);
    EXPECT_GT(empty, 50);
    EXPECT_THROW(scene.RenderToDepthImage(rendering::DepthFormat::kNormalized16, 1.0f, 1.0f),
                 core::Open3DError);
}

// Without near / far the depth images use the view's planes, and the reversed-Z image is
// Filament's convention near / z, checked where the splat wall (z = 4) alone is seen.
TEST_F(FilamentTest, DepthDefaultsFollowTheViewAndReversedZIsNearOverZ) {
    const camera::PinholeCamera camera = MakeFilamentTestCamera(96, 64);
    rendering::Open3DScene& scene = MakeOpen3DScene();
    scene.AddGeometry("wall", MakeSplatWall(4.0, 2.0, 24, Eigen::Vector3d(0.2, 0.6, 0.9)));
    AddRedSphere(scene.GetScene());
    scene.SetupCamera(camera);
    const float near = 0.25f, far = 8.0f;
    scene.SetClipPlanes(near, far);
    const t::geometry::Image z = scene.RenderToDepthImage(rendering::DepthFormat::kViewZ);
    const t::geometry::Image u_default =
        scene.RenderToDepthImage(rendering::DepthFormat::kNormalized16);
    const t::geometry::Image u_given =
        scene.RenderToDepthImage(rendering::DepthFormat::kNormalized16, near, far);
    const t::geometry::Image d = scene.RenderToDepthImage(rendering::DepthFormat::kReversedZ);
    // A different far plane must change the normalised image (the defaults are not ignored).
    const t::geometry::Image u_other =
        scene.RenderToDepthImage(rendering::DepthFormat::kNormalized16, near, 2.0f * far);
    ASSERT_EQ(d.GetDtype(), core::Dtype::Float32);
    int wall = 0, sphere = 0, differing = 0;
    for (int64_t i = 0; i < z.NumPixels(); ++i) {
        const float zi = z.Data<float>()[i];
        EXPECT_EQ(u_default.Data<uint16_t>()[i], u_given.Data<uint16_t>()[i]) << i;
        differing += u_other.Data<uint16_t>()[i] != u_given.Data<uint16_t>()[i];
        const float di = d.Data<float>()[i];
        if (zi <= 0.0f) {
            EXPECT_EQ(di, 0.0f) << i;
            continue;
        }
        // One float32 division: within 1 ulp of near / z.
        EXPECT_NEAR(di, near / zi, 1e-7f) << i;
        const int px = int(i % camera.width), py = int(i / camera.width);
        if (SphereDepthAt(camera, px, py, nullptr) > 0.0) {
            ++sphere;
        } else if (std::abs(zi - 4.0f) < 1e-4f) {
            // The wall's expected depth is 4 within float sums: d = 0.25 / 4.
            EXPECT_NEAR(di, 0.0625f, 2e-6f) << px << "," << py;
            ++wall;
        }
    }
    EXPECT_GT(wall, 500);
    EXPECT_GT(sphere, 100);
    EXPECT_GT(differing, 500);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
