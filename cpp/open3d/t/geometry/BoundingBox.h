// Boxes that select points (PointCloud::Crop), Open3D's two kinds: axis-aligned (min and
// max corners) and oriented (centre, rotation, edge lengths). Both are closed: a point on a
// face is inside.
#pragma once

#include <Eigen/Core>

#include <string>

namespace open3d {
namespace t {
namespace geometry {

class AxisAlignedBoundingBox {
public:
    /// An empty box (contains nothing) until bounds are set.
    AxisAlignedBoundingBox();
    /// Throws core::Open3DError when a bound is not finite or min_bound exceeds max_bound on
    /// an axis (naming the axis).
    AxisAlignedBoundingBox(const Eigen::Vector3d& min_bound, const Eigen::Vector3d& max_bound);

    const Eigen::Vector3d& GetMinBound() const { return min_bound_; }
    const Eigen::Vector3d& GetMaxBound() const { return max_bound_; }
    Eigen::Vector3d GetCenter() const { return 0.5 * (min_bound_ + max_bound_); }
    Eigen::Vector3d GetExtent() const { return max_bound_ - min_bound_; }
    bool IsEmpty() const { return empty_; }
    /// min_bound <= p <= max_bound on every axis (false for an empty box).
    bool Contains(const Eigen::Vector3d& p) const;
    std::string ToString() const;

private:
    Eigen::Vector3d min_bound_, max_bound_;
    bool empty_ = true;
};

class OrientedBoundingBox {
public:
    /// The box of edge lengths `extent` along the columns of R, centred at `center`: point p
    /// is inside when |R^T (p - center)| <= extent / 2 on every axis. Throws
    /// core::Open3DError for a non-finite value, a negative extent or an R that is not a
    /// rotation (orthonormal, determinant +1, within 1e-6).
    OrientedBoundingBox(const Eigen::Vector3d& center, const Eigen::Matrix3d& R,
                        const Eigen::Vector3d& extent);
    /// The axis-aligned box as an oriented one (R = I).
    static OrientedBoundingBox FromAxisAligned(const AxisAlignedBoundingBox& box);

    const Eigen::Vector3d& GetCenter() const { return center_; }
    const Eigen::Matrix3d& GetRotation() const { return R_; }
    const Eigen::Vector3d& GetExtent() const { return extent_; }
    bool Contains(const Eigen::Vector3d& p) const;
    std::string ToString() const;

private:
    Eigen::Vector3d center_;
    Eigen::Matrix3d R_;
    Eigen::Vector3d extent_;
};

}  // namespace geometry
}  // namespace t
}  // namespace open3d
