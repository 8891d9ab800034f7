#include "open3d/camera/PinholeCamera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "open3d/core/Exception.h"

namespace open3d {
namespace camera {

Eigen::Vector3d PinholeCamera::GetCenter() const {
    return -GetRotation().transpose() * GetTranslation();
}

Eigen::Vector3d PinholeCamera::PixelToWorld(double x, double y, double z) const {
    const Eigen::Vector3d view((x - cx) / fx * z, (y - cy) / fy * z, z);
    return GetRotation().transpose() * (view - GetTranslation());
}

void PinholeCamera::Validate() const {
    if (width <= 0 || height <= 0) {
        core::ThrowError("PinholeCamera: image size must be positive, got {}x{}", width, height);
    }
    if (!(std::isfinite(fx) && std::isfinite(fy) && fx > 0 && fy > 0)) {
        core::ThrowError("PinholeCamera: focal lengths must be positive, got fx={} fy={}", fx, fy);
    }
    if (!(std::isfinite(cx) && std::isfinite(cy)) || !world_to_camera.allFinite()) {
        core::ThrowError("PinholeCamera: principal point and extrinsic must be finite");
    }
    const Eigen::Matrix3d r = GetRotation();
    // 1e-6 accepts rotations read from JSON with ~16 digits and from float32 sources.
    if (!(r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6) ||
        std::abs(r.determinant() - 1.0) > 1e-6) {
        core::ThrowError("PinholeCamera: extrinsic rotation is not a proper rotation");
    }
}

PinholeCamera PinholeCamera::FromIntrinsic(const Eigen::Matrix3d& intrinsic,
                                           const Eigen::Matrix4d& extrinsic, int width,
                                           int height) {
    PinholeCamera camera;
    camera.width = width;
    camera.height = height;
    camera.fx = intrinsic(0, 0);
    camera.fy = intrinsic(1, 1);
    camera.cx = intrinsic(0, 2);
    camera.cy = intrinsic(1, 2);
    camera.world_to_camera = extrinsic;
    camera.Validate();
    return camera;
}

PinholeCamera PinholeCamera::ResizedKeepingAspect(int new_width, int new_height) const {
    if (new_width <= 0 && new_height <= 0) return *this;
    const int w = new_width > 0
                      ? new_width
                      : std::max(1, static_cast<int>(std::lround(static_cast<double>(new_height) *
                                                                 width / height)));
    const int h = new_height > 0
                      ? new_height
                      : std::max(1, static_cast<int>(std::lround(static_cast<double>(new_width) *
                                                                 height / width)));
    return Resized(w, h);
}

PinholeCamera PinholeCamera::Resized(int new_width, int new_height) const {
    if (new_width <= 0 || new_height <= 0) {
        core::ThrowError("PinholeCamera::Resized: size must be positive, got {}x{}", new_width,
                         new_height);
    }
    PinholeCamera out = *this;
    const double sx = static_cast<double>(new_width) / width;
    const double sy = static_cast<double>(new_height) / height;
    out.width = new_width;
    out.height = new_height;
    out.fx = fx * sx;
    out.fy = fy * sy;
    out.cx = (cx + 0.5) * sx - 0.5;
    out.cy = (cy + 0.5) * sy - 0.5;
    return out;
}

PinholeCamera PinholeCamera::FromLookAt(const LookAtCamera& look_at, int width, int height) {
    if (width <= 0 || height <= 0) {
        core::ThrowError("PinholeCamera::FromLookAt: size must be positive, got {}x{}", width,
                         height);
    }
    if (!(look_at.vertical_fov_deg > 0.0 && look_at.vertical_fov_deg < 180.0)) {
        core::ThrowError(
            "PinholeCamera::FromLookAt: vertical fov must be in (0, 180) degrees, "
            "got {}",
            look_at.vertical_fov_deg);
    }
    const Eigen::Vector3d forward_raw = look_at.center - look_at.eye;
    if (forward_raw.norm() == 0.0) core::ThrowError("PinholeCamera::FromLookAt: eye == center");
    const Eigen::Vector3d forward = forward_raw.normalized();
    const Eigen::Vector3d right_raw = forward.cross(look_at.up);
    if (right_raw.norm() < 1e-12 * std::max(1.0, look_at.up.norm())) {
        core::ThrowError("PinholeCamera::FromLookAt: up is parallel to the view direction");
    }
    const Eigen::Vector3d right = right_raw.normalized();
    const Eigen::Vector3d down = forward.cross(right);
    Eigen::Matrix3d r;
    r.row(0) = right.transpose();
    r.row(1) = down.transpose();
    r.row(2) = forward.transpose();

    PinholeCamera cam;
    cam.width = width;
    cam.height = height;
    const double tan_half = std::tan(look_at.vertical_fov_deg * std::numbers::pi / 360.0);
    cam.fy = height / (2.0 * tan_half);
    cam.fx = cam.fy;
    cam.cx = (width - 1) / 2.0;
    cam.cy = (height - 1) / 2.0;
    cam.world_to_camera.setIdentity();
    cam.world_to_camera.topLeftCorner<3, 3>() = r;
    cam.world_to_camera.topRightCorner<3, 1>() = -r * look_at.eye;
    return cam;
}

LookAtCamera PinholeCamera::ToLookAt(double target_distance) const {
    const Eigen::Matrix3d r = GetRotation();
    LookAtCamera out;
    out.eye = GetCenter();
    out.center = out.eye + r.row(2).transpose() * target_distance;
    out.up = -r.row(1).transpose();
    out.vertical_fov_deg = 2.0 * std::atan(height / (2.0 * fy)) * 180.0 / std::numbers::pi;
    return out;
}

LookAtCamera OrbitLookAt(const LookAtCamera& look_at, double angle_deg) {
    if (look_at.up.norm() == 0.0) core::ThrowError("OrbitLookAt: up must not be zero");
    const Eigen::AngleAxisd rotation(angle_deg * std::numbers::pi / 180.0, look_at.up.normalized());
    LookAtCamera out = look_at;
    out.eye = look_at.center + rotation * (look_at.eye - look_at.center);
    return out;
}

}  // namespace camera
}  // namespace open3d
