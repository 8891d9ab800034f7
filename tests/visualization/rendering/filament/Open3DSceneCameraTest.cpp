// Open3DScene camera setup: a cameras.json view scaled to a size, a bad index, and
// ResetCamera, which must put the whole bounding box of the scene inside the image.
#include <gtest/gtest.h>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "visualization/rendering/filament/FilamentTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using Open3DSceneCamera = FilamentTest;

TEST_F(Open3DSceneCamera, FromCamerasJson) {
    OPEN3D_REQUIRE_DATA("playbot/cameras.json");
    rendering::Open3DScene& scene = MakeOpen3DScene();
    const std::string path = DataPath("playbot/cameras.json");
    scene.SetupCameraFromJson(path, 3, 80, 60);
    const camera::PinholeCamera want = camera::ReadCamerasJson(path).at(3).camera.Resized(80, 60);
    EXPECT_EQ(scene.GetCamera().width, 80);
    EXPECT_EQ(scene.GetCamera().fx, want.fx);
    EXPECT_EQ(scene.GetCamera().world_to_camera, want.world_to_camera);
    try {
        scene.SetupCameraFromJson(path, 99);
        ADD_FAILURE() << "view 99 accepted";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("no view 99"), std::string::npos) << e.what();
    }
}

TEST_F(Open3DSceneCamera, ResetCameraFitsTheBounds) {
    rendering::Open3DScene& scene = MakeOpen3DScene();
    t::geometry::PointCloud wall = MakeSplatWall(0.0, 2.0, 5, Eigen::Vector3d(1, 1, 1));
    wall.Translate(Eigen::Vector3d(10, -3, 7));
    scene.AddGeometry("wall", wall);
    AddRedSphere(scene.GetScene());  // bounds now span both
    scene.ResetCamera(64, 48);
    const camera::PinholeCamera& cam = scene.GetCamera();
    Eigen::Vector3d lo, hi;
    ASSERT_TRUE(scene.GetScene().GetBounds(lo, hi));
    for (int corner = 0; corner < 8; ++corner) {
        const Eigen::Vector3d p((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                                (corner & 4) ? hi.z() : lo.z());
        const Eigen::Vector3d c = cam.GetRotation() * p + cam.GetTranslation();
        ASSERT_GT(c.z(), 0.0);
        const double u = cam.fx * c.x() / c.z() + cam.cx, v = cam.fy * c.y() / c.z() + cam.cy;
        EXPECT_GE(u, 0.0);
        EXPECT_LE(u, cam.width - 1.0);
        EXPECT_GE(v, 0.0);
        EXPECT_LE(v, cam.height - 1.0);
    }
    // And it is not absurdly far: the bounding sphere spans at least a third of the height.
    const Eigen::Vector3d center = 0.5 * (lo + hi);
    const double distance = (cam.GetCenter() - center).norm();
    EXPECT_GT(0.5 * (hi - lo).norm() / distance * cam.fy, cam.height / 3.0);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
