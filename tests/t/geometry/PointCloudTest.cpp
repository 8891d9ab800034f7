#include "open3d/t/geometry/PointCloud.h"

#include <gtest/gtest.h>

#include "open3d/core/Exception.h"

namespace open3d {
namespace t {
namespace geometry {
namespace {

using core::Dtype;
using core::Tensor;

PointCloud SplatCloud(int64_t n, int degree) {
    PointCloud cloud(Tensor({n, 3}, Dtype::Float32));
    cloud.SetPointAttr("scale", Tensor({n, 3}, Dtype::Float32));
    cloud.SetPointAttr("rot", Tensor({n, 4}, Dtype::Float32));
    cloud.SetPointAttr("opacity", Tensor({n, 1}, Dtype::Float32));
    cloud.SetPointAttr("f_dc", Tensor({n, 3}, Dtype::Float32));
    if (degree > 0)
        cloud.SetPointAttr("f_rest", Tensor({n, NumSHRestCoeffs(degree), 3}, Dtype::Float32));
    return cloud;
}

TEST(PointCloud, NumBytesCountsEveryAttribute) {
    // 5 splats of degree 2: 4 bytes x (3 + 3 + 4 + 1 + 3 + 8 x 3) = 152 bytes each.
    EXPECT_EQ(SplatCloud(5, 2).NumBytes(), 5 * 152);
    PointCloud cloud = SplatCloud(5, 0);
    cloud.SetPointAttr("label", Tensor({5, 1}, Dtype::UInt8));
    EXPECT_EQ(cloud.NumBytes(), 5 * 56 + 5);
    EXPECT_EQ(PointCloud().NumBytes(), 0);
}

TEST(PointCloud, GaussianSplatArraysPointAtTheAttributes) {
    const PointCloud d2 = SplatCloud(5, 2);
    const GaussianSplatArrays a = d2.GetGaussianSplatArrays();
    EXPECT_EQ(a.num_points, 5);
    EXPECT_EQ(a.sh_degree, 2);
    EXPECT_EQ(a.num_rest, 8);
    EXPECT_EQ(a.positions, d2.GetPointPositions().Data<float>());
    EXPECT_EQ(a.scale, d2.GetPointAttr("scale").Data<float>());
    EXPECT_EQ(a.rot, d2.GetPointAttr("rot").Data<float>());
    EXPECT_EQ(a.opacity, d2.GetPointAttr("opacity").Data<float>());
    EXPECT_EQ(a.f_dc, d2.GetPointAttr("f_dc").Data<float>());
    EXPECT_EQ(a.f_rest, d2.GetPointAttr("f_rest").Data<float>());

    const GaussianSplatArrays d0 = SplatCloud(3, 0).GetGaussianSplatArrays();
    EXPECT_EQ(d0.sh_degree, 0);
    EXPECT_EQ(d0.num_rest, 0);
    EXPECT_EQ(d0.f_rest, nullptr);

    PointCloud bad = SplatCloud(3, 1);
    bad.RemovePointAttr("rot");
    EXPECT_THROW(bad.GetGaussianSplatArrays(), core::Open3DError);
}

}  // namespace
}  // namespace geometry
}  // namespace t
}  // namespace open3d
