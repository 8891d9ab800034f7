#include "PointCloudOps.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <string>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatMerge.h"

namespace open3d {
namespace pybind {

namespace {

namespace gs = t::geometry::gs_attr;

// The relative tolerance PointCloud::Rotate allows (PointCloudTransform.cpp): matrices that
// went through float are that close to orthonormal; a visible shear is not.
constexpr double kRigidTolerance = 1e-6;

bool IsGaussianName(const std::string& name) {
    return name == gs::kPositions || name == gs::kScale || name == gs::kRot ||
           name == gs::kOpacity || name == gs::kFDc || name == gs::kFRest;
}

bool HasGaussianAttribute(const t::geometry::PointCloud& cloud) {
    return cloud.HasPointAttr(gs::kScale) || cloud.HasPointAttr(gs::kRot) ||
           cloud.HasPointAttr(gs::kFRest);
}

core::SizeVector WithRows(core::SizeVector shape, int64_t rows) {
    if (shape.empty()) shape.push_back(rows);
    shape[0] = rows;
    return shape;
}

// a's rows then b's, for one attribute of both clouds.
core::Tensor Concatenate(const std::string& name, const core::Tensor& a, const core::Tensor& b) {
    const core::SizeVector& sa = a.GetShape();
    const core::SizeVector& sb = b.GetShape();
    if (a.GetDtype() != b.GetDtype() || sa.size() != sb.size() ||
        !std::equal(sa.begin() + 1, sa.end(), sb.begin() + 1)) {
        core::ThrowError(
            "append: attribute '{}' differs in dtype or row shape between the clouds (shapes "
            "[{}] and [{}])",
            name, fmt::join(sa, ", "), fmt::join(sb, ", "));
    }
    core::Tensor out = core::Tensor::Empty(WithRows(sa, sa[0] + sb[0]), a.GetDtype());
    auto* bytes = static_cast<uint8_t*>(out.RawData());
    if (a.NumBytes() > 0) std::memcpy(bytes, a.RawData(), a.NumBytes());
    if (b.NumBytes() > 0) std::memcpy(bytes + a.NumBytes(), b.RawData(), b.NumBytes());
    return out;
}

}  // namespace

t::geometry::PointCloud Append(const t::geometry::PointCloud& a, const t::geometry::PointCloud& b) {
    const std::vector<std::string> names_a = a.GetPointAttrNames();
    const std::vector<std::string> names_b = b.GetPointAttrNames();
    if (names_a.empty()) return b;  // an empty PointCloud() adds nothing
    if (names_b.empty()) return a;
    const bool splats = a.IsGaussianSplat() && b.IsGaussianSplat();
    std::set<std::string> all(names_a.begin(), names_a.end());
    all.insert(names_b.begin(), names_b.end());
    for (const std::string& name : all) {
        // Splat clouds may differ in f_rest (SH degree): the merge pads the lower degree.
        if (splats && IsGaussianName(name)) continue;
        if (!a.HasPointAttr(name) || !b.HasPointAttr(name)) {
            core::ThrowError(
                "append: attribute '{}' is in one cloud only; both clouds need the same "
                "attributes (Gaussian splat clouds may differ in SH degree)",
                name);
        }
    }
    t::geometry::PointCloud out;
    if (splats) {
        out = visualization::rendering::MergeGaussianSplatClouds({&a, &b});
    } else {
        out.SetPointPositions(
            Concatenate(gs::kPositions, a.GetPointPositions(), b.GetPointPositions()));
    }
    for (const std::string& name : all) {
        if (out.HasPointAttr(name)) continue;
        out.SetPointAttr(name, Concatenate(name, a.GetPointAttr(name), b.GetPointAttr(name)));
    }
    return out;
}

Eigen::Vector3d Bound(const t::geometry::PointCloud& cloud, bool max) {
    // The library's box (zero corners for an empty cloud).
    const t::geometry::AxisAlignedBoundingBox box = cloud.GetAxisAlignedBoundingBox();
    return max ? box.GetMaxBound() : box.GetMinBound();
}

void TransformCloud(t::geometry::PointCloud& cloud, const Eigen::Matrix4d& transformation) {
    if (!transformation.allFinite()) core::ThrowError("transform: the matrix is not finite");
    if (transformation.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
        core::ThrowError(
            "transform: the last row must be (0, 0, 0, 1); a projective matrix has no meaning "
            "for a point cloud");
    }
    if (!HasGaussianAttribute(cloud)) {
        cloud.Transform(transformation);
        return;
    }
    const Eigen::Matrix3d A = transformation.topLeftCorner<3, 3>();
    const Eigen::Vector3d t = transformation.topRightCorner<3, 1>();
    // A = s R with R a rotation: det A = s^3, and A^T A = s^2 I.
    const double s = std::cbrt(A.determinant());
    if (!(std::abs(s) > 1e-12)) {
        core::ThrowError("transform: the matrix is singular (det {:.3g}): it collapses the splats",
                         A.determinant());
    }
    const Eigen::Matrix3d R = A / s;
    const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (!(error <= kRigidTolerance)) {
        core::ThrowError(
            "transform: a Gaussian splat cloud takes rotations, translations and uniform scales "
            "(upper 3x3 = s R); this matrix shears or scales unevenly (max |A^T A / s^2 - I| = "
            "{:.3g} with s = {:.6g}), which no splat's (rot, scale) can follow. Scale the "
            "splats uniformly, or transform the positions of a cloud without the Gaussian "
            "attributes",
            error, s);
    }
    // Scale and Rotate check the cloud before changing it, and R passed the test Rotate
    // makes, so nothing throws once the first of them has changed the cloud. They carry
    // scale, rot and the SH along; the positions are then set from the originals in one step
    // (A p + t rounded once to float, as a plain cloud's Transform gives them).
    const core::Tensor original = cloud.GetPointPositions();
    cloud.Scale(s, Eigen::Vector3d::Zero());
    cloud.Rotate(R, Eigen::Vector3d::Zero());
    const float* from = original.Data<float>();
    float* to = cloud.GetPointAttr(gs::kPositions).Data<float>();
    for (int64_t i = 0; i < cloud.NumPoints(); ++i) {
        const Eigen::Vector3d p(from[3 * i], from[3 * i + 1], from[3 * i + 2]);
        const Eigen::Vector3d q = A * p + t;
        for (int k = 0; k < 3; ++k) to[3 * i + k] = static_cast<float>(q[k]);
    }
}

}  // namespace pybind
}  // namespace open3d
