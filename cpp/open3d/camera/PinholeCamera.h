// A pinhole camera in OpenCV axes (x right, y down, z forward) with Open3D's pixel
// convention: pixel (u, v) has its centre at the integer coordinates (u, v), so the
// image centre is ((W - 1) / 2, (H - 1) / 2). This is exactly the 3DGS rasterizer's
// ndc2pix mapping ((v + 1) * S - 1) / 2 when cx, cy sit at the image centre.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace open3d {
namespace camera {

/// An Open3D-style look-at description of a camera.
struct LookAtCamera {
    Eigen::Vector3d eye = Eigen::Vector3d(0, 0, 1);
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    Eigen::Vector3d up = Eigen::Vector3d(0, 1, 0);
    /// Full vertical field of view in degrees.
    double vertical_fov_deg = 60.0;
};

/// Intrinsics plus a world-to-camera extrinsic. A point p_world projects to
/// p_cam = R p_world + t (R, t from world_to_camera), then to the pixel
/// (fx * x / z + cx, fy * y / z + cy).
struct PinholeCamera {
    int width = 0;
    int height = 0;
    double fx = 0.0;
    double fy = 0.0;
    double cx = 0.0;
    double cy = 0.0;
    Eigen::Matrix4d world_to_camera = Eigen::Matrix4d::Identity();

    /// World-to-camera rotation (rows are the camera axes in world space).
    Eigen::Matrix3d GetRotation() const { return world_to_camera.topLeftCorner<3, 3>(); }
    Eigen::Vector3d GetTranslation() const { return world_to_camera.topRightCorner<3, 1>(); }
    /// Camera centre in world space: -R^T t.
    Eigen::Vector3d GetCenter() const;
    /// The world point on the ray through pixel (x, y) (pixel centres on integers) at view
    /// depth z: R^T (((x - cx) / fx z, (y - cy) / fy z, z) - t). Picking's point.
    Eigen::Vector3d PixelToWorld(double x, double y, double z) const;
    /// tan of half the horizontal / vertical field of view as 3DGS defines it: W / (2 fx).
    double GetTanHalfFovX() const { return width / (2.0 * fx); }
    double GetTanHalfFovY() const { return height / (2.0 * fy); }
    /// x / z and y / z of the image's centre: ((W - 1) / 2 - cx) / fx, ((H - 1) / 2 - cy) / fy;
    /// 0 for a centred principal point. The renderers' Jacobian guard band (1.3 tan of the half
    /// field of view either side) is centred here, so an off-centre principal point (a crop, a
    /// tile of a larger view) does not clamp splats inside the image.
    double GetImageCenterTanX() const { return ((width - 1) / 2.0 - cx) / fx; }
    double GetImageCenterTanY() const { return ((height - 1) / 2.0 - cy) / fy; }

    /// Throws core::Open3DError when sizes or focal lengths are not positive or values
    /// are not finite, or the rotation is not orthonormal.
    void Validate() const;

    /// The same view at another image size: focal lengths scale with the size and the
    /// principal point keeps its place relative to the image (pixel-centre aware:
    /// cx' = (cx + 0.5) * W' / W - 0.5), so a centred principal point stays centred.
    PinholeCamera Resized(int new_width, int new_height) const;
    /// Resized where a size is given: 0 for one side takes it from the other with this
    /// camera's aspect ratio (rounded, at least 1); both 0 leave the camera as it is.
    PinholeCamera ResizedKeepingAspect(int new_width, int new_height) const;

    /// From a pinhole intrinsic matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (only those four
    /// entries are read) and a 4x4 world-to-camera extrinsic, OpenCV axes; validated.
    static PinholeCamera FromIntrinsic(const Eigen::Matrix3d& intrinsic,
                                       const Eigen::Matrix4d& extrinsic, int width, int height);

    /// A camera looking from eye to center, with `up` projected to the camera's -y axis.
    /// Square pixels, fy = H / (2 tan(fov / 2)), principal point at the image centre.
    /// Throws when eye == center, up is parallel to the view direction or fov is not in (0, 180).
    static PinholeCamera FromLookAt(const LookAtCamera& look_at, int width, int height);

    /// The look-at description of this camera: eye = centre, center = eye + forward *
    /// target_distance, up = the camera's -y axis, vertical fov = 2 atan(H / (2 fy)).
    LookAtCamera ToLookAt(double target_distance = 1.0) const;
};

/// Rotates a look-at camera's eye about the axis `up` through `center` by angle_deg
/// (right-handed), for orbit renders.
LookAtCamera OrbitLookAt(const LookAtCamera& look_at, double angle_deg);

}  // namespace camera
}  // namespace open3d
