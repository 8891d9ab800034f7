#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "TestUtility.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/camera/PinholeCamera.h"
#include "open3d/core/Exception.h"

namespace open3d {
namespace tests {

using camera::LookAtCamera;
using camera::PinholeCamera;

Eigen::Vector2d Project(const PinholeCamera& cam, const Eigen::Vector3d& p) {
    const Eigen::Vector3d v = cam.GetRotation() * p + cam.GetTranslation();
    return {cam.fx * v.x() / v.z() + cam.cx, cam.fy * v.y() / v.z() + cam.cy};
}

TEST(PinholeCamera, LookAtAxesAndIntrinsics) {
    LookAtCamera la;
    la.eye = {1, 2, 3};
    la.center = {1, 2, 0};
    la.up = {0, 1, 0};
    la.vertical_fov_deg = 90.0;
    const PinholeCamera cam = PinholeCamera::FromLookAt(la, 200, 100);
    // fov 90: tan(45) = 1, fy = H / 2.
    EXPECT_NEAR(cam.fy, 50.0, 1e-12);
    EXPECT_NEAR(cam.fx, 50.0, 1e-12);
    EXPECT_NEAR(cam.cx, 99.5, 1e-12);
    EXPECT_NEAR(cam.cy, 49.5, 1e-12);
    EXPECT_TRUE(cam.GetCenter().isApprox(la.eye, 1e-12));
    // The target lands on the principal point; +up goes up the image (smaller v, y down);
    // world +x is to the right for a camera looking down -z.
    EXPECT_TRUE(Project(cam, la.center).isApprox(Eigen::Vector2d(99.5, 49.5), 1e-12));
    EXPECT_LT(Project(cam, {1, 2.5, 0}).y(), 49.5);
    EXPECT_GT(Project(cam, {1.5, 2, 0}).x(), 99.5);
    EXPECT_NO_THROW(cam.Validate());
}

TEST(PinholeCamera, LookAtRoundTrip) {
    LookAtCamera la;
    la.eye = {0.3, -1.2, 2.0};
    la.center = {0.1, 0.2, -0.4};
    la.up = {0, 0, 1};
    la.vertical_fov_deg = 37.0;
    const PinholeCamera cam = PinholeCamera::FromLookAt(la, 640, 480);
    const double dist = (la.center - la.eye).norm();
    const LookAtCamera back = cam.ToLookAt(dist);
    EXPECT_TRUE(back.eye.isApprox(la.eye, 1e-12));
    EXPECT_TRUE(back.center.isApprox(la.center, 1e-12));
    EXPECT_NEAR(back.vertical_fov_deg, 37.0, 1e-12);
    // `up` comes back as the camera's up: orthogonalised, unit length, same half-space.
    EXPECT_NEAR(back.up.norm(), 1.0, 1e-12);
    EXPECT_GT(back.up.dot(la.up), 0.0);
    EXPECT_NEAR(back.up.dot(la.center - la.eye), 0.0, 1e-12);
    const PinholeCamera again = PinholeCamera::FromLookAt(back, 640, 480);
    EXPECT_TRUE(again.world_to_camera.isApprox(cam.world_to_camera, 1e-12));
}

TEST(PinholeCamera, LookAtErrors) {
    LookAtCamera la;
    la.center = la.eye;
    EXPECT_THROW(PinholeCamera::FromLookAt(la, 10, 10), core::Open3DError);
    la = LookAtCamera{};
    la.up = la.center - la.eye;
    EXPECT_THROW(PinholeCamera::FromLookAt(la, 10, 10), core::Open3DError);
    EXPECT_THROW(PinholeCamera::FromLookAt(LookAtCamera{}, 0, 10), core::Open3DError);
}

TEST(PinholeCamera, ResizedKeepsTheViewAndCentre) {
    PinholeCamera cam = PinholeCamera::FromLookAt(LookAtCamera{}, 800, 800);
    const PinholeCamera small = cam.Resized(64, 32);
    EXPECT_NEAR(small.fx, cam.fx * 64 / 800, 1e-12);
    EXPECT_NEAR(small.fy, cam.fy * 32 / 800, 1e-12);
    EXPECT_NEAR(small.cx, 31.5, 1e-12);
    EXPECT_NEAR(small.cy, 15.5, 1e-12);
    // A point keeps its relative place: (u + 0.5) / W is invariant.
    const Eigen::Vector3d p(0.1, -0.05, 0.0);
    const Eigen::Vector2d a = Project(cam, p), b = Project(small, p);
    EXPECT_NEAR((a.x() + 0.5) / 800, (b.x() + 0.5) / 64, 1e-12);
    EXPECT_NEAR((a.y() + 0.5) / 800, (b.y() + 0.5) / 32, 1e-12);
    EXPECT_THROW(cam.Resized(0, 10), core::Open3DError);
}

TEST(PinholeCamera, OrbitRotatesEyeAboutUp) {
    LookAtCamera la;
    la.eye = {0, 0, 2};
    la.center = {0, 0, 0};
    la.up = {0, 1, 0};
    const LookAtCamera o = camera::OrbitLookAt(la, 90.0);
    EXPECT_TRUE(o.eye.isApprox(Eigen::Vector3d(2, 0, 0), 1e-12));
}

void WriteFile(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(CamerasJson, ParsesViewsAsCameraToWorldRows) {
    const std::string text = R"([{"id": 7, "img_name": "a", "width": 100, "height": 50,
        "position": [1, 2, 3], "rotation": [[1, 0, 0], [0, 0, -1], [0, 1, 0]],
        "fx": 120.5, "fy": 110}])";
    const auto views = camera::ParseCamerasJson(text, "mem");
    ASSERT_EQ(views.size(), 1u);
    const PinholeCamera& cam = views[0].camera;
    EXPECT_EQ(views[0].id, 7);
    EXPECT_EQ(views[0].img_name, "a");
    EXPECT_EQ(cam.width, 100);
    EXPECT_EQ(cam.fx, 120.5);
    EXPECT_EQ(cam.cx, 49.5);
    EXPECT_EQ(cam.cy, 24.5);
    EXPECT_TRUE(cam.GetCenter().isApprox(Eigen::Vector3d(1, 2, 3), 1e-12));
    // Columns of the rotation are the camera axes: camera z (forward) = world -y here.
    const Eigen::Vector3d ahead = Eigen::Vector3d(1, 2, 3) + Eigen::Vector3d(0, -5, 0);
    EXPECT_TRUE((cam.GetRotation() * ahead + cam.GetTranslation())
                    .isApprox(Eigen::Vector3d(0, 0, 5), 1e-12));
}

TEST(CamerasJson, ErrorsNameFileEntryAndField) {
    const std::string dir = TempDir();
    auto expect_error = [&](const std::string& text, const std::string& needle) {
        const std::string path = dir + "/cameras.json";
        WriteFile(path, text);
        try {
            camera::ReadCamerasJson(path);
            ADD_FAILURE() << "no error for " << text;
        } catch (const core::Open3DError& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(path), std::string::npos) << msg;
            EXPECT_NE(msg.find(needle), std::string::npos) << msg;
        }
    };
    const std::string good =
        R"({"id": 0, "width": 8, "height": 8, "position": [0,0,0],
            "rotation": [[1,0,0],[0,1,0],[0,0,1]], "fx": 10, "fy": 10})";
    expect_error("[" + good + ", {\"id\": 1}]", "entry 1: missing field 'width'");
    expect_error("[{", "malformed JSON");
    expect_error("{}", "list");
    expect_error(R"([{"id": 0, "width": 8, "height": 8, "position": [0,0],
        "rotation": [[1,0,0],[0,1,0],[0,0,1]], "fx": 10, "fy": 10}])",
                 "'position'");
    expect_error(R"([{"id": 0, "width": 8, "height": 8, "position": [0,0,0],
        "rotation": [[2,0,0],[0,1,0],[0,0,1]], "fx": 10, "fy": 10}])",
                 "rotation");
    expect_error(R"([{"id": 0, "width": -8, "height": 8, "position": [0,0,0],
        "rotation": [[1,0,0],[0,1,0],[0,0,1]], "fx": 10, "fy": 10}])",
                 "size");
    EXPECT_THROW(camera::ReadCamerasJson(dir + "/missing.json"), core::Open3DError);
    // Found by fuzz_cameras_json: a number too large for a double made nlohmann throw
    // out_of_range (not parse_error), which escaped as a non-Open3D exception.
    expect_error(R"([{"id": 0, "width": 8, "height": 8, "position": [0,0,-0.7071e067811865476],
        "rotation": [[1,0,0],[0,1,0],[0,0,1]], "fx": 10, "fy": 10}])",
                 "malformed JSON");
    // Integers beyond int range are refused rather than wrapped.
    expect_error(R"([{"id": 0, "width": 8589934600, "height": 8, "position": [0,0,0],
        "rotation": [[1,0,0],[0,1,0],[0,0,1]], "fx": 10, "fy": 10}])",
                 "out of range");
}

TEST(CamerasJson, ReadsSharedPlaybotCameras) {
    OPEN3D_REQUIRE_DATA("playbot/cameras.json");
    const auto views = camera::ReadCamerasJson(DataPath("playbot/cameras.json"));
    ASSERT_EQ(views.size(), 24u);
    const PinholeCamera& cam = views[0].camera;
    EXPECT_EQ(cam.width, 800);
    EXPECT_NEAR(cam.fx, 857.8027682038235, 1e-9);
    EXPECT_NEAR(cam.GetCenter().y(), -1.1809856562363192, 1e-12);
    // The orbit views look at the origin region: it projects near the image centre.
    const Eigen::Vector3d v = cam.GetRotation() * Eigen::Vector3d::Zero() + cam.GetTranslation();
    EXPECT_GT(v.z(), 0.0);
    EXPECT_LT(std::abs(cam.fx * v.x() / v.z()), 400.0);
}

TEST(PinholeCamera, FromIntrinsicReadsFocalLengthsAndPrincipalPoint) {
    Eigen::Matrix3d K;
    K << 500, 0, 319.5, 0, 480, 239.5, 0, 0, 1;
    Eigen::Matrix4d extrinsic = Eigen::Matrix4d::Identity();
    extrinsic(2, 3) = 2.0;
    const camera::PinholeCamera cam = camera::PinholeCamera::FromIntrinsic(K, extrinsic, 640, 480);
    EXPECT_EQ(cam.width, 640);
    EXPECT_EQ(cam.height, 480);
    EXPECT_EQ(cam.fx, 500.0);
    EXPECT_EQ(cam.fy, 480.0);
    EXPECT_EQ(cam.cx, 319.5);
    EXPECT_EQ(cam.cy, 239.5);
    EXPECT_EQ(cam.world_to_camera, extrinsic);
    K(0, 0) = 0.0;  // validated: a focal length must be positive
    EXPECT_THROW(camera::PinholeCamera::FromIntrinsic(K, extrinsic, 640, 480), core::Open3DError);
}

TEST(PinholeCamera, PixelToWorldLiesOnThePixelsRayAtTheDepth) {
    camera::LookAtCamera look;
    look.eye = Eigen::Vector3d(0.3, -2, 5);
    look.center = Eigen::Vector3d(0, 0.5, 0);
    const camera::PinholeCamera cam = camera::PinholeCamera::FromLookAt(look, 80, 60);
    const Eigen::Vector3d p = cam.PixelToWorld(12.0, 40.0, 3.5);
    const Eigen::Vector3d v = cam.GetRotation() * p + cam.GetTranslation();
    EXPECT_NEAR(v.z(), 3.5, 1e-12);
    EXPECT_NEAR(cam.fx * v.x() / v.z() + cam.cx, 12.0, 1e-9);
    EXPECT_NEAR(cam.fy * v.y() / v.z() + cam.cy, 40.0, 1e-9);
}

}  // namespace tests
}  // namespace open3d
