// A built-in procedural splat scene (no files needed): a glossy sphere with view-dependent
// SH degree 3 colour, a translucent ring of elongated splats, and a checkered ground of
// flat splats. About 3,800 splats; gs-render draws it when no --input is given.
#pragma once

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace visualization {
namespace rendering {

/// The scene, SH degree 3, world +y up, centred near the origin. Deterministic.
t::geometry::PointCloud CreateDefaultGaussianSplatScene();

/// The look-at camera that frames the default scene (up = +y, 45 degree vertical fov).
camera::LookAtCamera GetDefaultSceneLookAt();

/// Where a mesh sphere shows depth compositing in the default scene: resting on the ground
/// in front of the splat sphere and crossing the ring, so some splats hide parts of it and
/// it hides others.
struct DefaultSceneMeshSphere {
    Eigen::Vector3d center;
    double radius = 0.0;
};
DefaultSceneMeshSphere GetDefaultSceneMeshSphere();

/// The default camera at a size (default 640x480).
camera::PinholeCamera GetDefaultSceneCamera(int width = 640, int height = 480);

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
