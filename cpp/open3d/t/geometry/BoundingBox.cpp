#include "open3d/t/geometry/BoundingBox.h"

#include <Eigen/Dense>

#include <cmath>

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace geometry {

namespace {

void RequireFinite(const char* what, const Eigen::Vector3d& v) {
    if (!v.allFinite()) {
        core::ThrowError("{}: ({}, {}, {}) is not finite", what, v.x(), v.y(), v.z());
    }
}

}  // namespace

AxisAlignedBoundingBox::AxisAlignedBoundingBox()
    : min_bound_(Eigen::Vector3d::Zero()), max_bound_(Eigen::Vector3d::Zero()) {}

AxisAlignedBoundingBox::AxisAlignedBoundingBox(const Eigen::Vector3d& min_bound,
                                               const Eigen::Vector3d& max_bound)
    : min_bound_(min_bound), max_bound_(max_bound), empty_(false) {
    RequireFinite("AxisAlignedBoundingBox min_bound", min_bound);
    RequireFinite("AxisAlignedBoundingBox max_bound", max_bound);
    for (int axis = 0; axis < 3; ++axis) {
        if (min_bound[axis] > max_bound[axis]) {
            core::ThrowError("AxisAlignedBoundingBox: min_bound {} exceeds max_bound {} on axis {}",
                             min_bound[axis], max_bound[axis], "xyz"[axis]);
        }
    }
}

bool AxisAlignedBoundingBox::Contains(const Eigen::Vector3d& p) const {
    return !empty_ && (p.array() >= min_bound_.array()).all() &&
           (p.array() <= max_bound_.array()).all();
}

std::string AxisAlignedBoundingBox::ToString() const {
    if (empty_) return "AxisAlignedBoundingBox: empty";
    return fmt::format("AxisAlignedBoundingBox: min ({}, {}, {}), max ({}, {}, {})", min_bound_.x(),
                       min_bound_.y(), min_bound_.z(), max_bound_.x(), max_bound_.y(),
                       max_bound_.z());
}

OrientedBoundingBox::OrientedBoundingBox(const Eigen::Vector3d& center, const Eigen::Matrix3d& R,
                                         const Eigen::Vector3d& extent)
    : center_(center), R_(R), extent_(extent) {
    RequireFinite("OrientedBoundingBox center", center);
    RequireFinite("OrientedBoundingBox extent", extent);
    if ((extent.array() < 0.0).any()) {
        core::ThrowError("OrientedBoundingBox: extent ({}, {}, {}) has a negative edge", extent.x(),
                         extent.y(), extent.z());
    }
    // The same tolerance as PointCloud::Rotate: matrices that went through float are that
    // close to orthonormal.
    constexpr double kTolerance = 1e-6;
    if (!R.allFinite() || (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > kTolerance ||
        std::abs(R.determinant() - 1.0) > kTolerance) {
        core::ThrowError(
            "OrientedBoundingBox: R is not a rotation (orthonormal with determinant +1; "
            "determinant {})",
            R.determinant());
    }
}

OrientedBoundingBox OrientedBoundingBox::FromAxisAligned(const AxisAlignedBoundingBox& box) {
    if (box.IsEmpty()) {
        core::ThrowError("OrientedBoundingBox::FromAxisAligned: the box is empty");
    }
    return OrientedBoundingBox(box.GetCenter(), Eigen::Matrix3d::Identity(), box.GetExtent());
}

bool OrientedBoundingBox::Contains(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d local = R_.transpose() * (p - center_);
    return (local.array().abs() <= 0.5 * extent_.array()).all();
}

std::string OrientedBoundingBox::ToString() const {
    return fmt::format("OrientedBoundingBox: center ({}, {}, {}), extent ({}, {}, {})", center_.x(),
                       center_.y(), center_.z(), extent_.x(), extent_.y(), extent_.z());
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
