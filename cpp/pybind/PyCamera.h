// Open3D's camera.PinholeCameraIntrinsic (an image size and a 3x3 matrix), which Open3D code
// hands to OffscreenRenderer.setup_camera; the renderer's own camera is PinholeCamera.
#pragma once

#include <Eigen/Core>

#include "open3d/camera/PinholeCamera.h"

namespace open3d {
namespace pybind {

struct PinholeCameraIntrinsic {
    int width = -1;  // Open3D's "not set"
    int height = -1;
    Eigen::Matrix3d intrinsic_matrix = Eigen::Matrix3d::Zero();
};

/// Throws core::Open3DError unless K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (no skew: the
/// rasterizer's projection has none). `what` names the caller.
void CheckIntrinsicMatrix(const Eigen::Matrix3d& K, const char* what);

/// The camera of an Open3D intrinsic and a world-to-camera extrinsic.
camera::PinholeCamera CameraFromIntrinsic(const PinholeCameraIntrinsic& intrinsic,
                                          const Eigen::Matrix4d& extrinsic);

}  // namespace pybind
}  // namespace open3d
