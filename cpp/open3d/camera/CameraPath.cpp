#include "open3d/camera/CameraPath.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include "open3d/core/Exception.h"

namespace open3d {
namespace camera {

namespace {

// log of a unit quaternion as the vector part of a pure quaternion: axis * half angle.
Eigen::Vector3d Log(const Eigen::Quaterniond& q) {
    const double n = q.vec().norm();
    if (n < 1e-15) return Eigen::Vector3d::Zero();
    return q.vec() / n * std::atan2(n, q.w());
}

Eigen::Quaterniond Exp(const Eigen::Vector3d& v) {
    const double n = v.norm();
    if (n < 1e-15) return Eigen::Quaterniond::Identity();
    const Eigen::Vector3d axis = v / n * std::sin(n);
    return Eigen::Quaterniond(std::cos(n), axis.x(), axis.y(), axis.z());
}

// Barry and Goldman's pyramid for a Catmull-Rom segment from p1 (s = 0) to p2 (s = 1) with
// centripetal knots (spacing |dp|^0.5). A zero spacing (two keyframes at one place) takes
// spacing 1 there, which only shapes the tangent.
Eigen::Vector3d CentripetalCatmullRom(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                      const Eigen::Vector3d& p2, const Eigen::Vector3d& p3,
                                      double s) {
    if ((p2 - p1).norm() == 0.0) return p1;  // no motion on this segment
    const auto spacing = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
        const double d = std::sqrt((b - a).norm());
        return d > 0.0 ? d : 1.0;
    };
    const double t0 = 0.0;
    const double t1 = t0 + spacing(p0, p1);
    const double t2 = t1 + spacing(p1, p2);
    const double t3 = t2 + spacing(p2, p3);
    const double t = t1 + s * (t2 - t1);
    const Eigen::Vector3d a1 = (t1 - t) / (t1 - t0) * p0 + (t - t0) / (t1 - t0) * p1;
    const Eigen::Vector3d a2 = (t2 - t) / (t2 - t1) * p1 + (t - t1) / (t2 - t1) * p2;
    const Eigen::Vector3d a3 = (t3 - t) / (t3 - t2) * p2 + (t - t2) / (t3 - t2) * p3;
    const Eigen::Vector3d b1 = (t2 - t) / (t2 - t0) * a1 + (t - t0) / (t2 - t0) * a2;
    const Eigen::Vector3d b2 = (t3 - t) / (t3 - t1) * a2 + (t - t1) / (t3 - t1) * a3;
    return (t2 - t) / (t2 - t1) * b1 + (t - t1) / (t2 - t1) * b2;
}

Eigen::Quaterniond CameraToWorld(const PinholeCamera& camera) {
    return Eigen::Quaterniond(Eigen::Matrix3d(camera.GetRotation().transpose())).normalized();
}

}  // namespace

CameraPath::CameraPath(std::vector<CameraKeyframe> keyframes) : keyframes_(std::move(keyframes)) {
    if (keyframes_.empty()) core::ThrowError("CameraPath: no keyframes");
    for (size_t i = 0; i < keyframes_.size(); ++i) {
        const CameraKeyframe& k = keyframes_[i];
        if (!std::isfinite(k.time))
            core::ThrowError("CameraPath: keyframe {}'s time is not finite", i);
        if (i > 0 && !(k.time > keyframes_[i - 1].time)) {
            core::ThrowError(
                "CameraPath: keyframe {} is at {} s, not after keyframe {} at {} s (times must "
                "increase)",
                i, k.time, i - 1, keyframes_[i - 1].time);
        }
        try {
            k.camera.Validate();
        } catch (const core::Open3DError& e) {
            core::ThrowError("CameraPath: keyframe {}: {}", i, e.what());
        }
        const PinholeCamera& first = keyframes_.front().camera;
        if (k.camera.width != first.width || k.camera.height != first.height) {
            core::ThrowError("CameraPath: keyframe {} is {}x{}, keyframe 0 {}x{} (one image size)",
                             i, k.camera.width, k.camera.height, first.width, first.height);
        }
    }
    // Rotations, each on the hemisphere of the one before, once for every At.
    for (size_t k = 0; k < keyframes_.size(); ++k) {
        rotations_.push_back(CameraToWorld(keyframes_[k].camera));
        if (k > 0 && rotations_[k].dot(rotations_[k - 1]) < 0.0) {
            rotations_[k].coeffs() = -rotations_[k].coeffs();
        }
    }
}

CameraPath CameraPath::FromViews(const std::vector<CameraView>& views,
                                 double seconds_per_keyframe) {
    if (!(seconds_per_keyframe > 0.0) || !std::isfinite(seconds_per_keyframe)) {
        core::ThrowError("CameraPath: seconds per keyframe must be positive, got {}",
                         seconds_per_keyframe);
    }
    const size_t timed = std::count_if(views.begin(), views.end(),
                                       [](const CameraView& v) { return v.time.has_value(); });
    if (timed != 0 && timed != views.size()) {
        core::ThrowError("CameraPath: {} of {} views have a 'time'; give every view one or none",
                         timed, views.size());
    }
    std::vector<CameraKeyframe> keyframes;
    for (size_t i = 0; i < views.size(); ++i) {
        keyframes.push_back(
            {timed ? *views[i].time : double(i) * seconds_per_keyframe, views[i].camera});
    }
    return CameraPath(std::move(keyframes));
}

PinholeCamera CameraPath::At(double time) const {
    const size_t n = keyframes_.size();
    if (n == 1 || !(time > keyframes_.front().time)) return keyframes_.front().camera;
    if (!(time < keyframes_.back().time)) return keyframes_.back().camera;
    // Segment i: keyframes i and i + 1 around `time`.
    const auto next =
        std::upper_bound(keyframes_.begin(), keyframes_.end(), time,
                         [](double value, const CameraKeyframe& k) { return value < k.time; });
    const size_t i = size_t(next - keyframes_.begin()) - 1;
    // A time within rounding of a keyframe's (i / fps against k x seconds per keyframe) is
    // that keyframe: its frame is the keyframe's camera exactly.
    for (size_t k : {i, i + 1}) {
        if (std::abs(keyframes_[k].time - time) <= 1e-9 * std::max(1.0, std::abs(time))) {
            return keyframes_[k].camera;
        }
    }
    const PinholeCamera& a = keyframes_[i].camera;
    const PinholeCamera& b = keyframes_[i + 1].camera;
    const double u = (time - keyframes_[i].time) / (keyframes_[i + 1].time - keyframes_[i].time);

    // Centres, with mirrored points past the ends.
    const auto centre = [&](size_t k) { return keyframes_[k].camera.GetCenter(); };
    const Eigen::Vector3d p1 = centre(i), p2 = centre(i + 1);
    const Eigen::Vector3d p0 = i > 0 ? centre(i - 1) : 2.0 * p1 - p2;
    const Eigen::Vector3d p3 = i + 2 < n ? centre(i + 2) : 2.0 * p2 - p1;
    const Eigen::Vector3d position = CentripetalCatmullRom(p0, p1, p2, p3, u);

    // The keyframes' rotations (made in the constructor) and squad's inner quaternions.
    const std::vector<Eigen::Quaterniond>& q = rotations_;
    const auto inner = [&](size_t k) {
        if (k == 0 || k + 1 == n) return q[k];
        const Eigen::Quaterniond inv = q[k].conjugate();
        return Eigen::Quaterniond(q[k] * Exp(-(Log(inv * q[k + 1]) + Log(inv * q[k - 1])) / 4.0));
    };
    const Eigen::Quaterniond outer = q[i].slerp(u, q[i + 1]);
    const Eigen::Quaterniond middle = inner(i).slerp(u, inner(i + 1));
    const Eigen::Quaterniond rotation = outer.slerp(2.0 * u * (1.0 - u), middle).normalized();

    PinholeCamera out = a;
    const Eigen::Matrix3d world_to_camera = rotation.toRotationMatrix().transpose();
    out.world_to_camera.setIdentity();
    out.world_to_camera.topLeftCorner<3, 3>() = world_to_camera;
    out.world_to_camera.topRightCorner<3, 1>() = -world_to_camera * position;
    // Fields of view (angles) and the principal point, linearly.
    const auto fov = [](double size, double focal) {
        return 2.0 * std::atan(size / (2.0 * focal));
    };
    const double fov_x = (1.0 - u) * fov(a.width, a.fx) + u * fov(b.width, b.fx);
    const double fov_y = (1.0 - u) * fov(a.height, a.fy) + u * fov(b.height, b.fy);
    out.fx = a.width / (2.0 * std::tan(fov_x / 2.0));
    out.fy = a.height / (2.0 * std::tan(fov_y / 2.0));
    out.cx = (1.0 - u) * a.cx + u * b.cx;
    out.cy = (1.0 - u) * a.cy + u * b.cy;
    return out;
}

size_t CameraPath::NumFrames(double fps) const {
    if (!(fps > 0.0) || !std::isfinite(fps)) {
        core::ThrowError("CameraPath: frames per second must be positive, got {}", fps);
    }
    // A hair of slack so that 10 s at 30 fps includes its last frame despite rounding.
    return size_t(std::floor(GetDuration() * fps + 1e-9)) + 1;
}

std::vector<PinholeCamera> CameraPath::Frames(double fps, size_t max_frames) const {
    const size_t count = NumFrames(fps);
    if (count > max_frames) {
        core::ThrowError("CameraPath: {} s at {} fps is {} frames, more than {}", GetDuration(),
                         fps, count, max_frames);
    }
    std::vector<PinholeCamera> frames;
    frames.reserve(count);
    for (size_t i = 0; i < count; ++i) frames.push_back(At(GetStartTime() + double(i) / fps));
    return frames;
}

}  // namespace camera
}  // namespace open3d
