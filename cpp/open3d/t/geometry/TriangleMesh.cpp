// TriangleMesh attributes, validation, bounds, normals and colors. Transforms live in
// TriangleMeshTransform.cpp, factories in TriangleMeshFactory.cpp.
#include "open3d/t/geometry/TriangleMesh.h"

#include <Eigen/Geometry>

#include <cmath>
#include <limits>

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace geometry {

using core::Dtype;
using core::ShapeToString;
using core::Tensor;

namespace {

bool IsFloat3Attr(const std::string& name) {
    return name == mesh_attr::kPositions || name == mesh_attr::kNormals ||
           name == mesh_attr::kColors;
}

void CheckFloat3(const std::string& name, const Tensor& value) {
    if (value.GetDtype() != Dtype::Float32 || value.NumDims() != 2 || value.GetShape(1) != 3) {
        core::ThrowError("TriangleMesh vertex attribute '{}' must be Float32 [N, 3], got {} {}",
                         name, core::DtypeName(value.GetDtype()), ShapeToString(value.GetShape()));
    }
}

Eigen::Vector3d Row3(const float* p, int64_t i) {
    return Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
}

}  // namespace

TriangleMesh::TriangleMesh(Tensor positions, TriangleIndices triangles)
    : triangles_(std::move(triangles)) {
    SetVertexPositions(std::move(positions));
}

int64_t TriangleMesh::NumVertices() const {
    auto it = vertex_attrs_.find(mesh_attr::kPositions);
    return it == vertex_attrs_.end() ? 0 : it->second.GetShape(0);
}

const Tensor& TriangleMesh::GetVertexAttr(const std::string& name) const {
    auto it = vertex_attrs_.find(name);
    if (it == vertex_attrs_.end())
        core::ThrowError("TriangleMesh has no vertex attribute '{}'", name);
    return it->second;
}

Tensor& TriangleMesh::GetVertexAttr(const std::string& name) {
    auto it = vertex_attrs_.find(name);
    if (it == vertex_attrs_.end())
        core::ThrowError("TriangleMesh has no vertex attribute '{}'", name);
    return it->second;
}

void TriangleMesh::SetVertexAttr(const std::string& name, Tensor value) {
    if (value.NumDims() < 1) {
        core::ThrowError("TriangleMesh vertex attribute '{}' needs rank >= 1", name);
    }
    if (IsFloat3Attr(name)) CheckFloat3(name, value);
    if (name == mesh_attr::kPositions) {
        for (const auto& [other_name, other] : vertex_attrs_) {
            if (other_name != name && other.GetShape(0) != value.GetShape(0)) {
                core::ThrowError("TriangleMesh positions have {} rows but '{}' has {}",
                                 value.GetShape(0), other_name, other.GetShape(0));
            }
        }
    } else if (HasVertexPositions() && value.GetShape(0) != NumVertices()) {
        core::ThrowError("TriangleMesh vertex attribute '{}' has {} rows, expected {}", name,
                         value.GetShape(0), NumVertices());
    }
    vertex_attrs_[name] = std::move(value);
}

std::vector<std::string> TriangleMesh::GetVertexAttrNames() const {
    std::vector<std::string> names;
    for (const auto& kv : vertex_attrs_) names.push_back(kv.first);
    return names;
}

void TriangleMesh::ValidateAttributeShapes() const {
    if (!HasVertexPositions()) {
        if (!vertex_attrs_.empty()) {
            core::ThrowError("TriangleMesh has vertex attribute '{}' but no positions",
                             vertex_attrs_.begin()->first);
        }
        return;
    }
    const int64_t n = NumVertices();
    for (const auto& [name, value] : vertex_attrs_) {
        if (IsFloat3Attr(name)) CheckFloat3(name, value);
        if (value.NumDims() < 1 || value.GetShape(0) != n) {
            core::ThrowError("TriangleMesh vertex attribute '{}' has shape {}, expected {} rows",
                             name, ShapeToString(value.GetShape()), n);
        }
    }
}

void TriangleMesh::ValidateTriangleIndices() const {
    const int64_t n = NumVertices();
    for (size_t t = 0; t < triangles_.size(); ++t) {
        for (int k = 0; k < 3; ++k) {
            const int index = triangles_[t][k];
            if (index < 0 || index >= n) {
                core::ThrowError(
                    "TriangleMesh triangle {} has vertex index {} out of range [0, {}) "
                    "(triangle ({}, {}, {}))",
                    t, index, n, triangles_[t][0], triangles_[t][1], triangles_[t][2]);
            }
        }
    }
}

void TriangleMesh::Validate() const {
    ValidateAttributeShapes();
    ValidateTriangleIndices();
    const int64_t n = NumVertices();
    if (n == 0) return;
    const float* p = GetVertexPositions().Data<float>();  // [N, 3]
    for (int64_t i = 0; i < n; ++i) {
        if (!Row3(p, i).allFinite()) {
            core::ThrowError("TriangleMesh vertex {} has a non-finite position ({}, {}, {})", i,
                             p[3 * i], p[3 * i + 1], p[3 * i + 2]);
        }
    }
    if (HasVertexNormals()) {
        const float* nrm = GetVertexNormals().Data<float>();  // [N, 3]
        for (int64_t i = 0; i < n; ++i) {
            if (!Row3(nrm, i).allFinite()) {
                core::ThrowError("TriangleMesh vertex {} has a non-finite normal ({}, {}, {})", i,
                                 nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
            }
        }
    }
    if (HasVertexColors()) {
        const float* c = GetVertexColors().Data<float>();  // [N, 3]
        for (int64_t i = 0; i < 3 * n; ++i) {
            // Written as !(in range) so that NaN is refused too.
            if (!(c[i] >= 0.f && c[i] <= 1.f)) {
                core::ThrowError("TriangleMesh vertex {} has color channel {} = {}, outside [0, 1]",
                                 i / 3, i % 3, c[i]);
            }
        }
    }
}

Eigen::Vector3d TriangleMesh::GetMinBound() const {
    if (NumVertices() == 0) return Eigen::Vector3d::Zero();
    const float* p = GetVertexPositions().Data<float>();  // [N, 3]
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    for (int64_t i = 0; i < NumVertices(); ++i) lo = lo.cwiseMin(Row3(p, i));
    return lo;
}

Eigen::Vector3d TriangleMesh::GetMaxBound() const {
    if (NumVertices() == 0) return Eigen::Vector3d::Zero();
    const float* p = GetVertexPositions().Data<float>();  // [N, 3]
    Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
    for (int64_t i = 0; i < NumVertices(); ++i) hi = hi.cwiseMax(Row3(p, i));
    return hi;
}

Eigen::Vector3d TriangleMesh::GetCenter() const {
    if (NumVertices() == 0) return Eigen::Vector3d::Zero();
    const float* p = GetVertexPositions().Data<float>();  // [N, 3]
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int64_t i = 0; i < NumVertices(); ++i) sum += Row3(p, i);
    return sum / double(NumVertices());
}

double TriangleMesh::GetSurfaceArea() const {
    Validate();
    if (triangles_.empty()) return 0.0;
    const float* p = GetVertexPositions().Data<float>();  // [N, 3]
    double area = 0.0;
    for (const Eigen::Vector3i& tri : triangles_) {
        const Eigen::Vector3d a = Row3(p, tri[0]);
        area += 0.5 * (Row3(p, tri[1]) - a).cross(Row3(p, tri[2]) - a).norm();
    }
    return area;
}

TriangleMesh& TriangleMesh::ComputeVertexNormals() {
    ValidateAttributeShapes();
    ValidateTriangleIndices();
    const int64_t n = NumVertices();
    if (n == 0) return *this;
    const float* p = GetVertexPositions().Data<float>();  // [N, 3]
    // Serial scatter in double: deterministic, and meshes beside splats are small.
    std::vector<Eigen::Vector3d> sums(n, Eigen::Vector3d::Zero());
    for (const Eigen::Vector3i& tri : triangles_) {
        const Eigen::Vector3d a = Row3(p, tri[0]);
        // |(b - a) x (c - a)| is twice the area, so the sum is area-weighted.
        const Eigen::Vector3d face = (Row3(p, tri[1]) - a).cross(Row3(p, tri[2]) - a);
        for (int k = 0; k < 3; ++k) sums[tri[k]] += face;
    }
    Tensor normals({n, 3}, Dtype::Float32);
    float* out = normals.Data<float>();
    for (int64_t i = 0; i < n; ++i) {
        const double length = sums[i].norm();
        const Eigen::Vector3d unit =
            length > 0.0 ? Eigen::Vector3d(sums[i] / length) : Eigen::Vector3d::Zero();
        for (int k = 0; k < 3; ++k) out[3 * i + k] = static_cast<float>(unit[k]);
    }
    SetVertexNormals(std::move(normals));
    return *this;
}

TriangleMesh& TriangleMesh::PaintUniformColor(const Eigen::Vector3d& rgb) {
    if (!((rgb.array() >= 0.0).all() && (rgb.array() <= 1.0).all())) {
        core::ThrowError("PaintUniformColor needs channels in [0, 1], got ({}, {}, {})", rgb.x(),
                         rgb.y(), rgb.z());
    }
    // Colors without positions would fail Validate and block a later SetVertexPositions.
    if (!HasVertexPositions()) core::ThrowError("PaintUniformColor needs vertex positions");
    const int64_t n = NumVertices();
    Tensor colors({n, 3}, Dtype::Float32);
    float* c = colors.Data<float>();
    for (int64_t i = 0; i < n; ++i) {
        for (int k = 0; k < 3; ++k) c[3 * i + k] = static_cast<float>(rgb[k]);
    }
    SetVertexColors(std::move(colors));
    return *this;
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
