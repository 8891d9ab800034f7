#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatMerge.h"

#include <algorithm>
#include <cstring>

#include "open3d/core/Exception.h"

namespace open3d {
namespace visualization {
namespace rendering {

t::geometry::PointCloud MergeGaussianSplatClouds(
    const std::vector<const t::geometry::PointCloud*>& clouds) {
    namespace gs = t::geometry::gs_attr;
    if (clouds.empty()) core::ThrowError("MergeGaussianSplatClouds: no clouds");
    int64_t n = 0;
    int degree = 0;
    std::vector<t::geometry::GaussianSplatArrays> arrays;
    for (const t::geometry::PointCloud* cloud : clouds) {
        cloud->ValidateGaussianSplat();
        arrays.push_back(cloud->GetGaussianSplatArrays());
        n += arrays.back().num_points;
        degree = std::max(degree, arrays.back().sh_degree);
    }
    const int rest = t::geometry::NumSHRestCoeffs(degree);
    core::Tensor positions = core::Tensor::Empty({n, 3}, core::Dtype::Float32);
    core::Tensor scale = core::Tensor::Empty({n, 3}, core::Dtype::Float32);
    core::Tensor rot = core::Tensor::Empty({n, 4}, core::Dtype::Float32);
    core::Tensor opacity = core::Tensor::Empty({n, 1}, core::Dtype::Float32);
    core::Tensor f_dc = core::Tensor::Empty({n, 3}, core::Dtype::Float32);
    core::Tensor f_rest;
    if (degree > 0) f_rest = core::Tensor({n, rest, 3}, core::Dtype::Float32);  // zeros
    int64_t at = 0;
    for (const t::geometry::GaussianSplatArrays& a : arrays) {
        const auto copy = [&](core::Tensor& dst, const float* src, int64_t width) {
            std::memcpy(dst.Data<float>() + at * width, src, sizeof(float) * a.num_points * width);
        };
        copy(positions, a.positions, 3);
        copy(scale, a.scale, 3);
        copy(rot, a.rot, 4);
        copy(opacity, a.opacity, 1);
        copy(f_dc, a.f_dc, 3);
        // Coefficient k of a lower degree is coefficient k of the higher one (bands in
        // order), so each splat's rows are a prefix of the merged rows.
        for (int64_t i = 0; a.num_rest > 0 && i < a.num_points; ++i) {
            std::memcpy(f_rest.Data<float>() + (at + i) * rest * 3, a.f_rest + i * a.num_rest * 3,
                        sizeof(float) * a.num_rest * 3);
        }
        at += a.num_points;
    }
    t::geometry::PointCloud merged(positions);
    merged.SetPointAttr(gs::kScale, scale);
    merged.SetPointAttr(gs::kRot, rot);
    merged.SetPointAttr(gs::kOpacity, opacity);
    merged.SetPointAttr(gs::kFDc, f_dc);
    if (degree > 0) merged.SetPointAttr(gs::kFRest, f_rest);
    return merged;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
