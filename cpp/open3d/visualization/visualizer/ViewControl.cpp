#include "open3d/visualization/visualizer/ViewControl.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "open3d/core/Exception.h"

namespace open3d {
namespace visualization {

namespace {

// Pitch stays this far from the poles: at +-90 degrees the view direction would be
// parallel to up and the look-at camera undefined.
constexpr double kMaxPitch = 89.0 * std::numbers::pi / 180.0;
constexpr double kMinDistance = 1e-6;

}  // namespace

ViewControl::ViewControl() { SetUp(Eigen::Vector3d(0, -1, 0)); }

void ViewControl::SetUp(const Eigen::Vector3d& up) {
    if (!(up.norm() > 0.0) || !up.allFinite()) {
        core::ThrowError("ViewControl: the up vector must be finite and non-zero");
    }
    up_ = up.normalized();
    // Home looks along +z (as Open3DScene::ResetCamera), or +x when z is (nearly) up.
    const Eigen::Vector3d axis =
        std::abs(up_.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
    home_forward_ = (axis - axis.dot(up_) * up_).normalized();
    yaw_ = pitch_ = 0.0;
}

void ViewControl::SetViewSize(int width, int height) {
    if (width <= 0 || height <= 0) {
        core::ThrowError("ViewControl: view size must be positive, got {}x{}", width, height);
    }
    width_ = width;
    height_ = height;
}

void ViewControl::SetVerticalFov(double degrees) {
    if (!(degrees > 0.0 && degrees < 180.0)) {
        core::ThrowError("ViewControl: vertical fov must be in (0, 180) degrees, got {}", degrees);
    }
    vertical_fov_deg_ = degrees;
}

void ViewControl::SetHomePitch(double degrees) {
    home_pitch_ = std::clamp(degrees * std::numbers::pi / 180.0, -kMaxPitch, kMaxPitch);
}

void ViewControl::FitBounds(const Eigen::Vector3d& min_bound, const Eigen::Vector3d& max_bound) {
    center_ = 0.5 * (min_bound + max_bound);
    const double radius = std::max(0.5 * (max_bound - min_bound).norm(), kMinDistance);
    const double half_v = 0.5 * vertical_fov_deg_ * std::numbers::pi / 180.0;
    const double half_h = std::atan(std::tan(half_v) * width_ / height_);
    // A sphere of radius r seen from distance d fills a half-angle asin(r / d).
    distance_ = radius / std::sin(std::min(half_v, half_h));
    yaw_ = 0.0;
    pitch_ = home_pitch_;
}

void ViewControl::SetLookAt(const camera::LookAtCamera& look_at) {
    SetVerticalFov(look_at.vertical_fov_deg);
    const Eigen::Vector3d offset = look_at.center - look_at.eye;
    if (!(offset.norm() > 0.0)) core::ThrowError("ViewControl: eye == center");
    const Eigen::Vector3d forward = offset.normalized();
    center_ = look_at.center;
    distance_ = offset.norm();
    Eigen::Vector3d horizontal = forward - forward.dot(up_) * up_;
    if (horizontal.norm() < 1e-9) horizontal = home_forward_;
    horizontal.normalize();
    // Yaw is measured from the home direction about up (right-handed).
    const Eigen::Vector3d cross = home_forward_.cross(horizontal);
    yaw_ = std::atan2(cross.dot(up_), home_forward_.dot(horizontal));
    pitch_ = std::clamp(std::asin(std::clamp(-forward.dot(up_), -1.0, 1.0)), -kMaxPitch, kMaxPitch);
}

void ViewControl::Rotate(double dx_pixels, double dy_pixels) {
    const double degrees_per_pixel = 180.0 / height_;
    Orbit(-dx_pixels * degrees_per_pixel, dy_pixels * degrees_per_pixel);
}

void ViewControl::Orbit(double yaw_degrees, double pitch_degrees) {
    const double to_radians = std::numbers::pi / 180.0;
    yaw_ += yaw_degrees * to_radians;
    pitch_ = std::clamp(pitch_ + pitch_degrees * to_radians, -kMaxPitch, kMaxPitch);
}

void ViewControl::Pan(double dx_pixels, double dy_pixels) {
    const camera::PinholeCamera camera = GetCamera();
    const Eigen::Matrix3d r = camera.GetRotation();  // rows: right, down, forward
    // A pixel at the centre's depth spans distance / fy world units.
    const double scale = distance_ / camera.fy;
    center_ -= scale * (dx_pixels * r.row(0).transpose() + dy_pixels * r.row(1).transpose());
}

void ViewControl::Zoom(double steps) {
    distance_ = std::max(distance_ * std::pow(0.9, steps), kMinDistance);
}

Eigen::Vector3d ViewControl::GetForward() const {
    const Eigen::Vector3d pitched = std::cos(pitch_) * home_forward_ - std::sin(pitch_) * up_;
    return Eigen::AngleAxisd(yaw_, up_) * pitched;
}

Eigen::Vector3d ViewControl::GetEye() const { return center_ - distance_ * GetForward(); }

camera::LookAtCamera ViewControl::GetLookAt() const {
    camera::LookAtCamera look_at;
    look_at.center = center_;
    look_at.eye = GetEye();
    look_at.up = up_;
    look_at.vertical_fov_deg = vertical_fov_deg_;
    return look_at;
}

camera::PinholeCamera ViewControl::GetCamera() const {
    return camera::PinholeCamera::FromLookAt(GetLookAt(), width_, height_);
}

}  // namespace visualization
}  // namespace open3d
