// A camera path: keyframed cameras and the cameras between them (docs/camera-paths.md).
// Positions follow a centripetal Catmull-Rom spline through the keyframes' centres (no cusps or
// self-intersections where keyframes bunch up), orientations a squad of their rotations (C1
// like the positions), the fields of view and the principal point change linearly. A time
// within 1e-9 (relative) of a keyframe's gives that keyframe's camera exactly.
#pragma once

#include <Eigen/Geometry>

#include <vector>

#include "open3d/camera/CamerasJson.h"
#include "open3d/camera/PinholeCamera.h"

namespace open3d {
namespace camera {

struct CameraKeyframe {
    double time = 0.0;  ///< seconds
    PinholeCamera camera;
};

/// Keyframes' spacing where their file gives no times, and the viewer's (gs-render's
/// --seconds-per-keyframe default, Python's CameraPath.from_cameras_json).
inline constexpr double kDefaultSecondsPerKeyframe = 2.0;

class CameraPath {
public:
    /// At least one keyframe, times finite and strictly increasing, every camera valid and of
    /// one image size. Throws core::Open3DError naming the keyframe otherwise.
    explicit CameraPath(std::vector<CameraKeyframe> keyframes);
    /// The views of a cameras.json as keyframes: at their "time" fields when every view has one,
    /// else `seconds_per_keyframe` apart from 0 (a mix is refused).
    static CameraPath FromViews(const std::vector<CameraView>& views, double seconds_per_keyframe);

    const std::vector<CameraKeyframe>& GetKeyframes() const { return keyframes_; }
    double GetStartTime() const { return keyframes_.front().time; }
    double GetDuration() const { return keyframes_.back().time - keyframes_.front().time; }
    /// The camera at `time` (clamped to the path's span).
    PinholeCamera At(double time) const;
    /// Frames at start + i / fps for i = 0 .. floor(duration * fps): 301 for 10 s at 30 fps
    /// (both ends). Throws for fps not positive and finite, or more than `max_frames`.
    std::vector<PinholeCamera> Frames(double fps, size_t max_frames = 1000000) const;
    /// The number of frames Frames(fps) gives.
    size_t NumFrames(double fps) const;

private:
    std::vector<CameraKeyframe> keyframes_;
    /// The keyframes' camera-to-world rotations, each on the hemisphere of the one before.
    std::vector<Eigen::Quaterniond> rotations_;
};

}  // namespace camera
}  // namespace open3d
