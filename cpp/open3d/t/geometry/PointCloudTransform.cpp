// Geometric transforms of point clouds; for Gaussian splat clouds every attribute follows
// (rot, scale, SH). Each method validates everything first and only then mutates, so a
// thrown error leaves the cloud unchanged.
#include <Eigen/Geometry>

#include <cmath>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/SHRotation.h"

namespace open3d {
namespace t {
namespace geometry {

namespace {

// A rotation matrix whose columns were computed in float (camera poses, quaternions
// stored as float) is orthonormal to ~1e-7; 1e-6 accepts those and still refuses any
// shear or non-uniform scale large enough to show up in float32 positions.
constexpr double kRotationTolerance = 1e-6;

bool IsFinite(const Eigen::MatrixXd& m) { return m.allFinite(); }

// p' = A p + t for every position, in double, rounded once to float.
void TransformPositions(core::Tensor& positions, const Eigen::Matrix3d& A,
                        const Eigen::Vector3d& t) {
    float* p = positions.Data<float>();  // [N, 3]
    core::ParallelFor(positions.GetShape(0), [&](int64_t i) {
        const Eigen::Vector3d v(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
        const Eigen::Vector3d out = A * v + t;
        for (int k = 0; k < 3; ++k) p[3 * i + k] = static_cast<float>(out[k]);
    });
}

// Splat attributes that Rotate and Scale change must be valid before anything moves.
// A cloud with any Gaussian attribute is treated as a splat cloud and must validate, so a
// malformed one is refused instead of being half transformed.
bool ValidateSplatAttributes(const PointCloud& cloud) {
    const bool has_any = cloud.HasPointAttr(gs_attr::kScale) || cloud.HasPointAttr(gs_attr::kRot) ||
                         cloud.HasPointAttr(gs_attr::kFRest);
    if (!has_any) return false;
    cloud.ValidateGaussianSplat();
    return true;
}

}  // namespace

Eigen::Vector3d PointCloud::GetCenter() const {
    if (!HasPointAttr(gs_attr::kPositions) || NumPoints() == 0) return Eigen::Vector3d::Zero();
    const int64_t n = NumPoints();
    const float* p = GetPointPositions().Data<float>();  // [N, 3]
    // Fixed blocks summed in order make the result independent of the thread count.
    constexpr int64_t kBlock = 1 << 16;
    const int64_t num_blocks = (n + kBlock - 1) / kBlock;
    std::vector<Eigen::Vector3d> partial(num_blocks, Eigen::Vector3d::Zero());
    core::ParallelFor(
        num_blocks,
        [&](int64_t b) {
            Eigen::Vector3d sum = Eigen::Vector3d::Zero();
            const int64_t end = std::min(n, (b + 1) * kBlock);
            for (int64_t i = b * kBlock; i < end; ++i) {
                sum += Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
            }
            partial[b] = sum;
        },
        1);
    Eigen::Vector3d total = Eigen::Vector3d::Zero();
    for (const auto& s : partial) total += s;
    return total / double(n);
}

PointCloud& PointCloud::Translate(const Eigen::Vector3d& translation, bool relative) {
    if (!translation.allFinite()) {
        core::ThrowError("Translate needs a finite translation, got ({}, {}, {})", translation.x(),
                         translation.y(), translation.z());
    }
    if (!HasPointAttr(gs_attr::kPositions) || NumPoints() == 0) return *this;
    const Eigen::Vector3d t = relative ? translation : Eigen::Vector3d(translation - GetCenter());
    TransformPositions(GetPointAttr(gs_attr::kPositions), Eigen::Matrix3d::Identity(), t);
    return *this;
}

PointCloud& PointCloud::Rotate(const Eigen::Matrix3d& R, const Eigen::Vector3d& center) {
    if (!IsFinite(R) || !center.allFinite()) {
        core::ThrowError("Rotate needs a finite rotation matrix and center");
    }
    const double orthonormality_error =
        (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    const double det = R.determinant();
    // Written as !(x <= tol) so that NaN-producing input is refused too.
    if (!(orthonormality_error <= kRotationTolerance)) {
        core::ThrowError(
            "Rotate needs an orthonormal matrix: max |R^T R - I| = {:.3g} exceeds {:.1g}. Use "
            "Scale for uniform scaling or Transform for general matrices",
            orthonormality_error, kRotationTolerance);
    }
    if (!(std::abs(det - 1.0) <= kRotationTolerance)) {
        core::ThrowError(
            "Rotate needs a proper rotation (det +1), got det = {:.6g}; a reflection cannot be "
            "applied to Gaussian splats as a rotation (use Scale(-1) for a point inversion)",
            det);
    }
    if (!HasPointAttr(gs_attr::kPositions)) return *this;
    const bool is_splat = ValidateSplatAttributes(*this);
    const int degree = is_splat ? GaussianSplatGetSHOrder() : 0;
    // Built before any mutation: it is the last step that can throw.
    const SHRotation sh_rotation(R, degree);

    // p' = R (p - c) + c = R p + (c - R c); the translation is exactly zero for R = I.
    TransformPositions(GetPointAttr(gs_attr::kPositions), R, center - R * center);
    if (!is_splat) return *this;

    // Sigma' = R Sigma R^T = (R R_q) S^2 (R R_q)^T, so q' = q_R * q (Hamilton product).
    const Eigen::Quaterniond q_r = Eigen::Quaterniond(R).normalized();
    float* rot = GetPointAttr(gs_attr::kRot).Data<float>();  // [N, 4] (w, x, y, z)
    core::ParallelFor(NumPoints(), [&](int64_t i) {
        float* q = rot + 4 * i;
        const Eigen::Quaterniond q_old(q[0], q[1], q[2], q[3]);
        const Eigen::Quaterniond q_new = q_r * q_old;
        q[0] = static_cast<float>(q_new.w());
        q[1] = static_cast<float>(q_new.x());
        q[2] = static_cast<float>(q_new.y());
        q[3] = static_cast<float>(q_new.z());
    });
    if (degree > 0) {
        RotateSHRest(sh_rotation, NumPoints(), GetPointAttr(gs_attr::kFRest).Data<float>());
    }
    return *this;
}

PointCloud& PointCloud::Scale(double scale, const Eigen::Vector3d& center) {
    if (!std::isfinite(scale) || !center.allFinite()) {
        core::ThrowError("Scale needs a finite factor and center, got {}", scale);
    }
    if (!HasPointAttr(gs_attr::kPositions)) return *this;
    const bool is_splat = ValidateSplatAttributes(*this);
    if (is_splat && scale == 0.0) {
        core::ThrowError(
            "Scale(0) would collapse every Gaussian of a splat cloud to a degenerate one");
    }
    const int degree = is_splat ? GaussianSplatGetSHOrder() : 0;

    // p' = s (p - c) + c = s p + (1 - s) c.
    TransformPositions(GetPointAttr(gs_attr::kPositions), scale * Eigen::Matrix3d::Identity(),
                       (1.0 - scale) * center);
    if (!is_splat) return *this;

    // Sigma' = s^2 Sigma: the linear scales take |s|, the quaternion is unchanged because a
    // negative s is the point inversion -I (which commutes with every rotation) times |s|.
    const double abs_scale = std::abs(scale);
    float* s = GetPointAttr(gs_attr::kScale).Data<float>();  // [N, 3]
    core::ParallelFor(NumPoints() * 3,
                      [&](int64_t i) { s[i] = static_cast<float>(s[i] * abs_scale); });
    if (scale < 0.0 && degree > 0) {
        ApplySHParity(degree, NumPoints(), GetPointAttr(gs_attr::kFRest).Data<float>());
    }
    return *this;
}

PointCloud& PointCloud::Transform(const Eigen::Matrix4d& transformation) {
    if (!IsFinite(transformation)) core::ThrowError("Transform needs a finite 4x4 matrix");
    if (transformation.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
        core::ThrowError(
            "Transform needs an affine matrix with last row (0, 0, 0, 1); a projective matrix "
            "has no meaning for a point cloud");
    }
    if (!HasPointAttr(gs_attr::kPositions)) return *this;
    if (IsGaussianSplat()) {
        // A general matrix may shear or scale non-uniformly, which no (rot, scale) pair
        // can follow exactly; we do not guess. Rotate/Scale/Translate update everything.
        core::LogWarning(
            "Transform(4x4) on a Gaussian splat cloud moves positions only; the Gaussian "
            "attributes (scale, rot, f_dc, f_rest) are unchanged. Use Rotate, Scale and "
            "Translate to transform splats.");
    }
    TransformPositions(GetPointAttr(gs_attr::kPositions), transformation.topLeftCorner<3, 3>(),
                       transformation.topRightCorner<3, 1>());
    return *this;
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
