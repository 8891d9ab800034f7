// Camera paths (CameraPath.h): keyframes come back exactly, the spline and squad have the
// values worked out by hand on simple paths, the path is C1 where keyframes join, and bad
// keyframes are refused naming the keyframe.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "open3d/camera/CameraPath.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"

namespace open3d {
namespace tests {
namespace {

using camera::CameraKeyframe;
using camera::CameraPath;
using camera::LookAtCamera;
using camera::PinholeCamera;

PinholeCamera LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& center, double fov = 60.0) {
    LookAtCamera look;
    look.eye = eye;
    look.center = center;
    look.up = Eigen::Vector3d(0, -1, 0);
    look.vertical_fov_deg = fov;
    return PinholeCamera::FromLookAt(look, 64, 48);
}

// The camera's forward axis (its third row of world_to_camera) in world space.
Eigen::Vector3d Forward(const PinholeCamera& c) { return c.GetRotation().row(2).transpose(); }

TEST(CameraPath, KeyframeTimesGiveTheKeyframesExactly) {
    const CameraPath path({{0.0, LookAt({0, 0, -5}, {0, 0, 0})},
                           {1.5, LookAt({3, 1, -4}, {0, 0, 0}, 50)},
                           {4.0, LookAt({5, 0, 0}, {0, 1, 0}, 40)}});
    for (const CameraKeyframe& k : path.GetKeyframes()) {
        const PinholeCamera c = path.At(k.time);
        EXPECT_EQ(c.world_to_camera, k.camera.world_to_camera);
        EXPECT_EQ(c.fx, k.camera.fx);
    }
    // Outside the span: the end keyframes.
    EXPECT_EQ(path.At(-1.0).world_to_camera, path.GetKeyframes().front().camera.world_to_camera);
    EXPECT_EQ(path.At(9.0).world_to_camera, path.GetKeyframes().back().camera.world_to_camera);
    EXPECT_DOUBLE_EQ(path.GetDuration(), 4.0);
}

TEST(CameraPath, EvenlySpacedPointsOnALineMoveAlongIt) {
    // Centres 0, 1, 2, 3 on x, one second apart, one orientation: by symmetry the centripetal
    // spline stays on the line and is at x = 1.5 half way through the middle segment; the
    // rotation does not change.
    std::vector<CameraKeyframe> keys;
    for (int i = 0; i < 4; ++i)
        keys.push_back({double(i), LookAt({double(i), 0, -5}, {double(i), 0, 0})});
    const CameraPath path(keys);
    const PinholeCamera mid = path.At(1.5);
    EXPECT_NEAR(mid.GetCenter().x(), 1.5, 1e-12);
    EXPECT_NEAR(mid.GetCenter().y(), 0.0, 1e-12);
    EXPECT_NEAR(mid.GetCenter().z(), -5.0, 1e-12);
    EXPECT_LT((mid.GetRotation() - keys[0].camera.GetRotation()).norm(), 1e-12);
    for (double t = 0.0; t <= 3.0; t += 0.1) {
        EXPECT_NEAR(path.At(t).GetCenter().y(), 0.0, 1e-12) << t;
        EXPECT_NEAR(path.At(t).GetCenter().z(), -5.0, 1e-12) << t;
    }
}

TEST(CameraPath, TwoKeyframesTurnAtAConstantRateAndChangeTheFieldOfViewLinearly) {
    // Two keyframes 90 degrees apart about the vertical axis: squad reduces to slerp (its inner
    // quaternions are the keyframes at the ends), so a quarter of the way the camera has
    // turned 22.5 degrees; the vertical field of view goes 60 -> 40 degrees linearly.
    const CameraPath path(
        {{0.0, LookAt({0, 0, 0}, {0, 0, 1}, 60)}, {2.0, LookAt({0, 0, 0}, {1, 0, 0}, 40)}});
    const PinholeCamera c = path.At(0.5);
    const double angle = std::atan2(Forward(c).x(), Forward(c).z());
    EXPECT_NEAR(angle, M_PI / 8, 1e-12);
    const double fov = 2.0 * std::atan(c.height / (2.0 * c.fy)) * 180.0 / M_PI;
    EXPECT_NEAR(fov, 55.0, 1e-9);
    EXPECT_NEAR(c.GetCenter().norm(), 0.0, 1e-12);  // the centre does not move
}

TEST(CameraPath, PositionAndOrientationTurnWithoutAKinkAtKeyframes) {
    // An orbit-like path of five keyframes at uneven times: at each inner keyframe the
    // one-sided derivatives of the centre and of the forward axis point the same way (the
    // spline and squad are tangent-continuous; their speed may change there,
    // docs/camera-paths.md). Finite differences with h = 1e-6 s leave a direction error of
    // O(h x curvature), measured below 1e-5; a kink would show as an angle of tenths.
    std::vector<CameraKeyframe> keys;
    const double times[5] = {0.0, 1.0, 2.5, 3.0, 5.0};
    for (int i = 0; i < 5; ++i) {
        const double a = 0.7 * i;
        keys.push_back({times[i], LookAt({4 * std::sin(a), 0.5 * i, -4 * std::cos(a)}, {0, 0, 0})});
    }
    const CameraPath path(keys);
    const double h = 1e-6;
    const auto direction_change = [](const Eigen::Vector3d& l, const Eigen::Vector3d& r) {
        return (l.normalized() - r.normalized()).norm();
    };
    for (int i = 1; i < 4; ++i) {
        const double t = times[i];
        const Eigen::Vector3d left = path.At(t).GetCenter() - path.At(t - h).GetCenter();
        const Eigen::Vector3d right = path.At(t + h).GetCenter() - path.At(t).GetCenter();
        EXPECT_LT(direction_change(left, right), 1e-4) << "position at keyframe " << i;
        const Eigen::Vector3d fl = Forward(path.At(t)) - Forward(path.At(t - h));
        const Eigen::Vector3d fr = Forward(path.At(t + h)) - Forward(path.At(t));
        EXPECT_LT(direction_change(fl, fr), 1e-4) << "rotation at keyframe " << i;
    }
    // Between keyframes the path is smooth too (no kink inside a segment).
    const Eigen::Vector3d l = path.At(1.7).GetCenter() - path.At(1.7 - h).GetCenter();
    const Eigen::Vector3d r = path.At(1.7 + h).GetCenter() - path.At(1.7).GetCenter();
    EXPECT_LT(direction_change(l, r), 1e-4);
}

TEST(CameraPath, FramesCoverBothEnds) {
    const CameraPath path(
        {{0.0, LookAt({0, 0, -5}, {0, 0, 0})}, {10.0, LookAt({5, 0, 0}, {0, 0, 0})}});
    EXPECT_EQ(path.NumFrames(30.0), 301u);
    const std::vector<PinholeCamera> frames = path.Frames(30.0);
    ASSERT_EQ(frames.size(), 301u);
    EXPECT_EQ(frames.back().world_to_camera, path.GetKeyframes().back().camera.world_to_camera);
    EXPECT_THROW(path.Frames(0.0), core::Open3DError);
    EXPECT_THROW(path.Frames(30.0, 300), core::Open3DError);  // over the cap
}

TEST(CameraPath, ViewsBecomeKeyframesByTheirTimesOrEvenlySpaced) {
    const std::string json = R"([
      {"id": 0, "width": 64, "height": 48, "fx": 50, "fy": 50, "position": [0, 0, -5],
       "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]},
      {"id": 1, "width": 64, "height": 48, "fx": 50, "fy": 50, "position": [1, 0, -5],
       "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}])";
    std::vector<camera::CameraView> views = camera::ParseCamerasJson(json, "test.json");
    EXPECT_DOUBLE_EQ(CameraPath::FromViews(views, 2.5).GetDuration(), 2.5);
    views[0].time = 1.0;
    EXPECT_THROW(CameraPath::FromViews(views, 2.5), core::Open3DError);  // one timed, one not
    views[1].time = 4.0;
    EXPECT_DOUBLE_EQ(CameraPath::FromViews(views, 2.5).GetDuration(), 3.0);
    const std::string timed = R"([{"id": 0, "width": 8, "height": 8, "fx": 5, "fy": 5, "time": "x",
       "position": [0, 0, 0], "rotation": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}])";
    EXPECT_THROW(camera::ParseCamerasJson(timed, "t.json"), core::Open3DError);
}

TEST(CameraPath, BadKeyframesAreRefusedByNumber) {
    const PinholeCamera a = LookAt({0, 0, -5}, {0, 0, 0});
    try {
        CameraPath({{0.0, a}, {1.0, a}, {1.0, a}});
        ADD_FAILURE() << "two keyframes at one time";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("keyframe 2 is at 1 s"), std::string::npos)
            << e.what();
    }
    PinholeCamera wide = a;
    wide.width = 65;
    EXPECT_THROW(CameraPath({{0.0, a}, {1.0, wide}}), core::Open3DError);
    EXPECT_THROW(CameraPath(std::vector<CameraKeyframe>{}), core::Open3DError);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
