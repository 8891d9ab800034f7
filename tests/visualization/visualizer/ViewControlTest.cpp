// The orbit camera alone (no window): fitting bounds puts every corner in the image, orbit
// keeps the centre and distance, pan and zoom move what they should.
#include "open3d/visualization/visualizer/ViewControl.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "open3d/core/Exception.h"

namespace open3d {
namespace tests {
namespace {

using visualization::ViewControl;

// Pixel (u, v) and depth z of a world point.
Eigen::Vector3d Project(const camera::PinholeCamera& camera, const Eigen::Vector3d& p) {
    const Eigen::Vector3d c = camera.GetRotation() * p + camera.GetTranslation();
    return Eigen::Vector3d(camera.fx * c.x() / c.z() + camera.cx,
                           camera.fy * c.y() / c.z() + camera.cy, c.z());
}

std::array<Eigen::Vector3d, 8> Corners(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    std::array<Eigen::Vector3d, 8> out;
    for (int i = 0; i < 8; ++i) {
        out[i] = Eigen::Vector3d(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(),
                                 i & 4 ? hi.z() : lo.z());
    }
    return out;
}

// Every corner in front of the camera and inside [-0.5, W - 0.5] x [-0.5, H - 0.5] (the
// pixel edges; pixel centres are at integers).
void ExpectBoundsInView(const camera::PinholeCamera& camera, const Eigen::Vector3d& lo,
                        const Eigen::Vector3d& hi) {
    for (const Eigen::Vector3d& corner : Corners(lo, hi)) {
        const Eigen::Vector3d p = Project(camera, corner);
        EXPECT_GT(p.z(), 0.0) << corner.transpose();
        EXPECT_GE(p.x(), -0.5) << corner.transpose();
        EXPECT_LE(p.x(), camera.width - 0.5) << corner.transpose();
        EXPECT_GE(p.y(), -0.5) << corner.transpose();
        EXPECT_LE(p.y(), camera.height - 0.5) << corner.transpose();
    }
}

struct FitCase {
    int width, height;
    double fov;
    Eigen::Vector3d up;
    double home_pitch;
};

TEST(ViewControl, FitBoundsPutsEveryCornerInView) {
    const Eigen::Vector3d lo(-3.0, 0.5, 10.0), hi(1.0, 2.0, 17.0);
    for (const FitCase& c :
         {FitCase{640, 400, 60.0, {0, -1, 0}, 0.0},
          FitCase{400, 640, 60.0, {0, -1, 0}, 20.0},  // tall: horizontal fov limits
          FitCase{1280, 720, 30.0, {0, 1, 0}, -30.0}, FitCase{100, 100, 90.0, {0, 0, 1}, 45.0},
          FitCase{300, 200, 45.0, {1, 1, 0}, 10.0}}) {
        SCOPED_TRACE(testing::Message() << c.width << "x" << c.height << " fov " << c.fov);
        ViewControl view;
        view.SetUp(c.up);
        view.SetViewSize(c.width, c.height);
        view.SetVerticalFov(c.fov);
        view.SetHomePitch(c.home_pitch);
        view.FitBounds(lo, hi);
        ExpectBoundsInView(view.GetCamera(), lo, hi);
        EXPECT_TRUE(view.GetCenter().isApprox(0.5 * (lo + hi)));
        // Orbiting keeps the bounding sphere, hence the corners, in view.
        for (double yaw : {37.0, 140.0, -95.0}) {
            view.Orbit(yaw, 15.0);
            ExpectBoundsInView(view.GetCamera(), lo, hi);
        }
    }
}

TEST(ViewControl, FitIsTightForTheLimitingFov) {
    // A cube seen at 90 degrees vertical fov in a square view: the bounding sphere (radius
    // sqrt(3)) touches the image edges, so distance = sqrt(3) / sin(45 degrees).
    ViewControl view;
    view.SetViewSize(100, 100);
    view.SetVerticalFov(90.0);
    view.FitBounds(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1));
    EXPECT_NEAR(view.GetDistance(), std::sqrt(3.0) / std::sin(M_PI / 4), 1e-12);
}

TEST(ViewControl, HomeViewLooksAlongZWithUpMinusY) {
    ViewControl view;  // 3DGS default: up = -y
    view.FitBounds(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1));
    EXPECT_TRUE(view.GetForward().isApprox(Eigen::Vector3d(0, 0, 1)));
    const camera::PinholeCamera camera = view.GetCamera();
    // World -y is up in the image: a point above the centre lands in a smaller row.
    EXPECT_LT(Project(camera, Eigen::Vector3d(0, -0.5, 0)).y(), camera.cy);
}

TEST(ViewControl, OrbitKeepsCentreAndDistance) {
    ViewControl view;
    view.FitBounds(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 2, 2));
    const Eigen::Vector3d center = view.GetCenter();
    const double distance = view.GetDistance();
    const Eigen::Vector3d eye = view.GetEye();
    view.Rotate(120.0, -40.0);
    EXPECT_TRUE(view.GetCenter().isApprox(center));
    EXPECT_NEAR((view.GetEye() - center).norm(), distance, 1e-12);
    EXPECT_GT((view.GetEye() - eye).norm(), 0.1 * distance);
    // A drag across the full height turns by 180 degrees: the eye goes to the other side.
    ViewControl half;
    half.SetViewSize(640, 400);
    half.FitBounds(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1));
    half.Rotate(400.0, 0.0);
    EXPECT_TRUE(half.GetForward().isApprox(Eigen::Vector3d(0, 0, -1), 1e-12));
}

TEST(ViewControl, PitchStopsShortOfThePoles) {
    ViewControl view;
    view.Orbit(0.0, 500.0);
    EXPECT_LT(std::abs(view.GetForward().dot(view.GetUp())), 1.0);
    EXPECT_NO_THROW(view.GetCamera());
    view.Orbit(0.0, -1000.0);
    EXPECT_NO_THROW(view.GetCamera());
}

TEST(ViewControl, PanMovesTheCentreWithTheCursor) {
    ViewControl view;
    view.SetViewSize(640, 400);
    view.FitBounds(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1));
    const Eigen::Vector3d center = view.GetCenter();
    const camera::PinholeCamera before = view.GetCamera();
    view.Pan(50.0, -20.0);
    // The old centre now appears where the cursor moved to: (cx + 50, cy - 20).
    const Eigen::Vector3d p = Project(view.GetCamera(), center);
    EXPECT_NEAR(p.x(), before.cx + 50.0, 1e-9);
    EXPECT_NEAR(p.y(), before.cy - 20.0, 1e-9);
    EXPECT_NEAR(view.GetDistance(), (view.GetEye() - view.GetCenter()).norm(), 1e-12);
}

TEST(ViewControl, ZoomScalesTheDistance) {
    ViewControl view;
    view.FitBounds(Eigen::Vector3d::Constant(-1), Eigen::Vector3d::Constant(1));
    const double d = view.GetDistance();
    view.Zoom(2.0);
    EXPECT_NEAR(view.GetDistance(), d * 0.81, 1e-12);
    view.Zoom(-2.0);
    EXPECT_NEAR(view.GetDistance(), d, 1e-12);
    view.Zoom(1e6);  // never reaches the centre
    EXPECT_GT(view.GetDistance(), 0.0);
}

TEST(ViewControl, SetLookAtRoundTrips) {
    ViewControl view;
    camera::LookAtCamera look_at;
    look_at.eye = Eigen::Vector3d(1.0, -2.0, -3.0);
    look_at.center = Eigen::Vector3d(0.5, 0.0, 1.0);
    look_at.up = Eigen::Vector3d(0, -1, 0);
    look_at.vertical_fov_deg = 50.0;
    view.SetLookAt(look_at);
    EXPECT_TRUE(view.GetEye().isApprox(look_at.eye, 1e-12));
    EXPECT_TRUE(view.GetCenter().isApprox(look_at.center, 1e-12));
    EXPECT_DOUBLE_EQ(view.GetVerticalFov(), 50.0);
}

TEST(ViewControl, BadArgumentsThrow) {
    ViewControl view;
    EXPECT_THROW(view.SetUp(Eigen::Vector3d::Zero()), core::Open3DError);
    EXPECT_THROW(view.SetViewSize(0, 10), core::Open3DError);
    EXPECT_THROW(view.SetVerticalFov(180.0), core::Open3DError);
    camera::LookAtCamera same;
    same.eye = same.center;
    EXPECT_THROW(view.SetLookAt(same), core::Open3DError);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
