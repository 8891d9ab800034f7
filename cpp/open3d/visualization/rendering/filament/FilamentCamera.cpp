#include "open3d/visualization/rendering/filament/FilamentCamera.h"

#include <filament/Camera.h>
#include <math/mat4.h>

#include <Eigen/Dense>

namespace open3d {
namespace visualization {
namespace rendering {

void SetFilamentCamera(filament::Camera& camera, const camera::PinholeCamera& pinhole,
                       double near) {
    const double w = pinhole.width, h = pinhole.height;
    // GL camera coordinates are OpenCV's with y and z negated. Pixel u's centre sits at
    // window x = u + 0.5, i.e. ndc_x = (2 u + 1) / W - 1; rows count from the top, GL's
    // window y from the bottom: ndc_y = 1 - (2 v + 1) / H. Written with clip w = -z_gl:
    filament::math::mat4 p(0.0);  // column-major: p[column][row]
    p[0][0] = 2.0 * pinhole.fx / w;
    p[2][0] = 1.0 - (2.0 * pinhole.cx + 1.0) / w;
    p[1][1] = 2.0 * pinhole.fy / h;
    p[2][1] = (2.0 * pinhole.cy + 1.0) / h - 1.0;
    // Infinite far plane: ndc_z = 1 - 2 near / z, which Filament maps to d = near / z.
    p[2][2] = -1.0;
    p[3][2] = -2.0 * near;
    p[2][3] = -1.0;
    // The far value only bounds Filament's culling; the matrix itself has no far plane.
    camera.setCustomProjection(p, near, 1e6);

    Eigen::Matrix4d gl_to_cv = Eigen::Matrix4d::Identity();
    gl_to_cv(1, 1) = gl_to_cv(2, 2) = -1.0;
    const Eigen::Matrix4d camera_to_world = pinhole.world_to_camera.inverse() * gl_to_cv;
    filament::math::mat4f model;
    for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) model[c][r] = static_cast<float>(camera_to_world(r, c));
    }
    camera.setModelMatrix(model);
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
