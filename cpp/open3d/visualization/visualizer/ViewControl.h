// The viewer's camera as an orbit around a centre (docs/viewer.md "Camera"): a fixed world
// up axis, yaw about it, pitch towards it (clamped short of the poles so the view never
// rolls), and a distance. Mouse and keys move these; GetCamera() turns them into the
// PinholeCamera the renderer uses. Pure math, no window: tests drive it directly.
#pragma once

#include <Eigen/Core>

#include "open3d/camera/PinholeCamera.h"

namespace open3d {
namespace visualization {

class ViewControl {
public:
    /// World up (3DGS / COLMAP scenes: -y, the default), the view size in pixels and the
    /// full vertical field of view.
    ViewControl();

    /// Throws core::Open3DError for a zero vector. Resets yaw and pitch: the home view
    /// looks along +z (+x when `up` is nearly z), made perpendicular to `up`.
    void SetUp(const Eigen::Vector3d& up);
    const Eigen::Vector3d& GetUp() const { return up_; }
    /// Throws unless both are positive.
    void SetViewSize(int width, int height);
    int GetWidth() const { return width_; }
    int GetHeight() const { return height_; }
    /// Full vertical field of view in degrees, in (0, 180).
    void SetVerticalFov(double degrees);
    double GetVerticalFov() const { return vertical_fov_deg_; }

    /// Pitch of the home orientation in degrees (default 0: level; > 0 looks down).
    void SetHomePitch(double degrees);
    /// Home orientation, centred on the box, at the distance where the box's bounding
    /// sphere fits both the vertical and the horizontal field of view (so every corner
    /// projects inside the image).
    void FitBounds(const Eigen::Vector3d& min_bound, const Eigen::Vector3d& max_bound);
    /// Takes the eye, centre and fov of `look_at` (its up is replaced by the world up; a
    /// view straight along the up axis is tilted to the pitch limit).
    void SetLookAt(const camera::LookAtCamera& look_at);

    /// Orbits by a mouse drag of (dx, dy) pixels: a drag across the full view height turns
    /// the camera by 180 degrees. Dragging right turns the scene right.
    void Rotate(double dx_pixels, double dy_pixels);
    /// Orbits by angles: yaw about the up axis (right-handed), pitch towards looking down.
    void Orbit(double yaw_degrees, double pitch_degrees);
    /// Moves the centre so that the point under the cursor follows a drag of (dx, dy) pixels.
    void Pan(double dx_pixels, double dy_pixels);
    /// Dolly towards the centre: the distance is multiplied by 0.9^steps (positive = closer).
    void Zoom(double steps);

    const Eigen::Vector3d& GetCenter() const { return center_; }
    double GetDistance() const { return distance_; }
    Eigen::Vector3d GetEye() const;
    /// Unit view direction (from the eye to the centre).
    Eigen::Vector3d GetForward() const;
    camera::LookAtCamera GetLookAt() const;
    /// The camera at the view size (FromLookAt: square pixels, centred principal point).
    camera::PinholeCamera GetCamera() const;

private:
    Eigen::Vector3d up_;
    Eigen::Vector3d home_forward_;  // perpendicular to up_
    Eigen::Vector3d center_ = Eigen::Vector3d::Zero();
    double distance_ = 1.0;
    double yaw_ = 0.0, pitch_ = 0.0;  // radians; pitch > 0 looks down on the centre
    double home_pitch_ = 0.0;
    int width_ = 640, height_ = 480;
    double vertical_fov_deg_ = 60.0;
};

}  // namespace visualization
}  // namespace open3d
