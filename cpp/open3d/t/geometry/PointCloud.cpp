#include "open3d/t/geometry/PointCloud.h"

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace geometry {

using core::Dtype;
using core::ShapeToString;
using core::Tensor;

PointCloud::PointCloud(Tensor positions) { SetPointPositions(std::move(positions)); }

int64_t PointCloud::NumPoints() const {
    auto it = attrs_.find(gs_attr::kPositions);
    return it == attrs_.end() ? 0 : it->second.GetShape(0);
}

const Tensor& PointCloud::GetPointAttr(const std::string& name) const {
    auto it = attrs_.find(name);
    if (it == attrs_.end()) core::ThrowError("PointCloud has no attribute '{}'", name);
    return it->second;
}

Tensor& PointCloud::GetPointAttr(const std::string& name) {
    auto it = attrs_.find(name);
    if (it == attrs_.end()) core::ThrowError("PointCloud has no attribute '{}'", name);
    return it->second;
}

void PointCloud::SetPointAttr(const std::string& name, Tensor value) {
    if (value.NumDims() < 1) core::ThrowError("PointCloud attribute '{}' needs rank >= 1", name);
    if (name == gs_attr::kPositions) {
        if (value.GetDtype() != Dtype::Float32 || value.NumDims() != 2 || value.GetShape(1) != 3) {
            core::ThrowError("PointCloud positions must be Float32 [N, 3], got {} {}",
                             core::DtypeName(value.GetDtype()), ShapeToString(value.GetShape()));
        }
        for (const auto& [other_name, other] : attrs_) {
            if (other_name != name && other.GetShape(0) != value.GetShape(0)) {
                core::ThrowError("PointCloud positions have {} rows but '{}' has {}",
                                 value.GetShape(0), other_name, other.GetShape(0));
            }
        }
    } else if (HasPointAttr(gs_attr::kPositions) && value.GetShape(0) != NumPoints()) {
        core::ThrowError("PointCloud attribute '{}' has {} rows, expected {}", name,
                         value.GetShape(0), NumPoints());
    }
    attrs_[name] = std::move(value);
}

std::vector<std::string> PointCloud::GetPointAttrNames() const {
    std::vector<std::string> names;
    for (const auto& kv : attrs_) names.push_back(kv.first);
    return names;
}

int64_t PointCloud::NumBytes() const {
    int64_t bytes = 0;
    for (const auto& kv : attrs_) bytes += kv.second.NumBytes();
    return bytes;
}

void PointCloud::ValidateGaussianSplat() const {
    const int64_t n = NumPoints();
    auto check = [&](const char* name, const core::SizeVector& expected) {
        const Tensor& t = GetPointAttr(name);
        if (t.GetDtype() != Dtype::Float32 || t.GetShape() != expected) {
            core::ThrowError("Gaussian attribute '{}' must be Float32 {}, got {} {}", name,
                             ShapeToString(expected), core::DtypeName(t.GetDtype()),
                             ShapeToString(t.GetShape()));
        }
    };
    if (!HasPointAttr(gs_attr::kPositions))
        core::ThrowError("Gaussian splat cloud has no positions");
    check(gs_attr::kScale, {n, 3});
    check(gs_attr::kRot, {n, 4});
    check(gs_attr::kOpacity, {n, 1});
    check(gs_attr::kFDc, {n, 3});
    if (HasPointAttr(gs_attr::kFRest)) {
        const Tensor& f_rest = GetPointAttr(gs_attr::kFRest);
        const int64_t nc = f_rest.NumDims() == 3 ? f_rest.GetShape(1) : -1;
        if (nc != 3 && nc != 8 && nc != 15) {
            core::ThrowError(
                "Gaussian attribute 'f_rest' must be Float32 [N, Nc, 3] with Nc in "
                "{{3, 8, 15}} (SH degree 1..3), got {}",
                ShapeToString(f_rest.GetShape()));
        }
        check(gs_attr::kFRest, {n, nc, 3});
    }
}

bool PointCloud::IsGaussianSplat() const {
    for (const char* name : {gs_attr::kScale, gs_attr::kRot, gs_attr::kOpacity, gs_attr::kFDc}) {
        if (!HasPointAttr(name)) return false;
    }
    try {
        ValidateGaussianSplat();
    } catch (const core::Open3DError&) {
        return false;
    }
    return true;
}

int PointCloud::GaussianSplatGetSHOrder() const {
    ValidateGaussianSplat();
    if (!HasPointAttr(gs_attr::kFRest)) return 0;
    switch (GetPointAttr(gs_attr::kFRest).GetShape(1)) {
        case 3:
            return 1;
        case 8:
            return 2;
        default:
            return 3;
    }
}

GaussianSplatArrays PointCloud::GetGaussianSplatArrays() const {
    GaussianSplatArrays a;
    a.sh_degree = GaussianSplatGetSHOrder();  // validates
    a.num_rest = NumSHRestCoeffs(a.sh_degree);
    a.num_points = NumPoints();
    a.positions = GetPointPositions().Data<float>();
    a.scale = GetPointAttr(gs_attr::kScale).Data<float>();
    a.rot = GetPointAttr(gs_attr::kRot).Data<float>();
    a.opacity = GetPointAttr(gs_attr::kOpacity).Data<float>();
    a.f_dc = GetPointAttr(gs_attr::kFDc).Data<float>();
    if (a.sh_degree > 0) a.f_rest = GetPointAttr(gs_attr::kFRest).Data<float>();
    return a;
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
