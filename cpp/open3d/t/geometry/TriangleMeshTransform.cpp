// Geometric transforms of triangle meshes. Positions map by p' = A p + t; normals by the
// inverse transpose of A (which keeps them perpendicular to the surface under non-uniform
// scale and shear), renormalised; a mirror (det A < 0) reverses the winding so that front
// faces stay counter-clockwise from outside. Everything is checked before anything changes.
#include <Eigen/LU>

#include <cmath>
#include <utility>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/t/geometry/TriangleMesh.h"

namespace open3d {
namespace t {
namespace geometry {

namespace {

// Same tolerance as PointCloud::Rotate: accepts rotation matrices computed in float and
// refuses any shear or scale that would show in float32 positions.
constexpr double kRotationTolerance = 1e-6;

// p' = A p + t for every row, in double, rounded once to float.
void TransformRows(core::Tensor& rows, const Eigen::Matrix3d& A, const Eigen::Vector3d& t) {
    float* p = rows.Data<float>();  // [N, 3]
    core::ParallelFor(rows.GetShape(0), [&](int64_t i) {
        const Eigen::Vector3d out = A * Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]) + t;
        for (int k = 0; k < 3; ++k) p[3 * i + k] = static_cast<float>(out[k]);
    });
}

// n' = normalize(M n); zero normals (vertices without a face) stay zero.
void TransformNormals(core::Tensor& normals, const Eigen::Matrix3d& M) {
    float* n = normals.Data<float>();  // [N, 3]
    core::ParallelFor(normals.GetShape(0), [&](int64_t i) {
        const Eigen::Vector3d v = M * Eigen::Vector3d(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
        const double length = v.norm();
        const Eigen::Vector3d out = length > 0.0 ? Eigen::Vector3d(v / length) : v;
        for (int k = 0; k < 3; ++k) n[3 * i + k] = static_cast<float>(out[k]);
    });
}

}  // namespace

void TriangleMesh::ApplyAffine(const Eigen::Matrix3d& A, const Eigen::Vector3d& t) {
    ValidateAttributeShapes();
    const double det = A.determinant();
    Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Identity();
    if (HasVertexNormals()) {
        const Eigen::FullPivLU<Eigen::Matrix3d> lu(A);
        if (!lu.isInvertible()) {
            core::ThrowError(
                "TriangleMesh: a singular linear part (det = {:.3g}) leaves vertex normals "
                "undefined; remove them first (RemoveVertexAttr(\"normals\")) and call "
                "ComputeVertexNormals() afterwards if needed",
                det);
        }
        normal_matrix = lu.inverse().transpose();
    }
    if (!HasVertexPositions()) return;

    TransformRows(GetVertexAttr(mesh_attr::kPositions), A, t);
    if (HasVertexNormals()) TransformNormals(GetVertexAttr(mesh_attr::kNormals), normal_matrix);
    // A mirror turns counter-clockwise into clockwise; swapping two corners turns it back.
    if (det < 0.0) {
        for (Eigen::Vector3i& tri : triangles_) std::swap(tri[1], tri[2]);
    }
}

TriangleMesh& TriangleMesh::Translate(const Eigen::Vector3d& translation, bool relative) {
    if (!translation.allFinite()) {
        core::ThrowError("Translate needs a finite translation, got ({}, {}, {})", translation.x(),
                         translation.y(), translation.z());
    }
    ValidateAttributeShapes();
    if (NumVertices() == 0) return *this;
    const Eigen::Vector3d t = relative ? translation : Eigen::Vector3d(translation - GetCenter());
    TransformRows(GetVertexAttr(mesh_attr::kPositions), Eigen::Matrix3d::Identity(), t);
    return *this;
}

TriangleMesh& TriangleMesh::Scale(double scale, const Eigen::Vector3d& center) {
    if (!std::isfinite(scale) || !center.allFinite()) {
        core::ThrowError("Scale needs a finite factor and center, got {}", scale);
    }
    // p' = s (p - c) + c = s p + (1 - s) c.
    ApplyAffine(scale * Eigen::Matrix3d::Identity(), (1.0 - scale) * center);
    return *this;
}

TriangleMesh& TriangleMesh::Rotate(const Eigen::Matrix3d& R, const Eigen::Vector3d& center) {
    if (!R.allFinite() || !center.allFinite()) {
        core::ThrowError("Rotate needs a finite rotation matrix and center");
    }
    const double orthonormality_error =
        (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (!(orthonormality_error <= kRotationTolerance)) {
        core::ThrowError(
            "Rotate needs an orthonormal matrix: max |R^T R - I| = {:.3g} exceeds {:.1g}. Use "
            "Scale for uniform scaling or Transform for general matrices",
            orthonormality_error, kRotationTolerance);
    }
    // p' = R (p - c) + c; for orthonormal R the inverse transpose is R itself.
    ApplyAffine(R, center - R * center);
    return *this;
}

TriangleMesh& TriangleMesh::Transform(const Eigen::Matrix4d& transformation) {
    if (!transformation.allFinite()) core::ThrowError("Transform needs a finite 4x4 matrix");
    if (transformation.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
        core::ThrowError(
            "Transform needs an affine matrix with last row (0, 0, 0, 1); projective matrices "
            "are not supported for meshes");
    }
    ApplyAffine(transformation.topLeftCorner<3, 3>(), transformation.topRightCorner<3, 1>());
    return *this;
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
