// A PinholeCamera (OpenCV axes, Open3D's pixel-centre convention) as a Filament camera, so
// meshes land on exactly the pixels the splat rasterizer uses (docs/filament.md "Camera").
#pragma once

#include "open3d/camera/PinholeCamera.h"

namespace filament {
class Camera;
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

/// Sets `camera`'s model matrix (camera to world, GL axes: y up, looking down -z) and an
/// infinite-far perspective projection built from the intrinsics: pixel (u, v), row 0 at
/// the top, has its centre at (fx x / z + cx, fy y / z + cy). Filament turns it into
/// reversed-Z, so its depth buffer holds d = near / z_view (0 where nothing was drawn).
void SetFilamentCamera(filament::Camera& camera, const camera::PinholeCamera& pinhole, double near);

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
