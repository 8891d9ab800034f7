// A random Gaussian splat cloud for the t/io tests (round trips of every format, the
// level-of-detail hierarchy's file).
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/io/FileFormats.h"

namespace open3d {
namespace t {
namespace io {

// A random splat cloud whose scales come from float log-scales, as every PLY-read cloud does.
inline geometry::PointCloud RandomCloud(int64_t n, int degree, uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> normal(0.0f, 1.0f);
    std::uniform_real_distribution<float> log_scale(-9.0f, 3.0f);
    auto fill = [&](const core::SizeVector& shape, auto gen) {
        core::Tensor t(shape, core::Dtype::Float32);
        for (int64_t i = 0; i < t.NumElements(); ++i) t.Data<float>()[i] = gen();
        return t;
    };
    geometry::PointCloud cloud(fill({n, 3}, [&] { return 10.0f * normal(rng); }));
    cloud.SetPointAttr("scale", fill({n, 3}, [&] { return DecodeLogScale(log_scale(rng)); }));
    core::Tensor rot({n, 4}, core::Dtype::Float32);
    for (int64_t i = 0; i < n; ++i) {
        double q[4], norm = 0;
        for (double& v : q) {
            v = normal(rng);
            norm += v * v;
        }
        for (int k = 0; k < 4; ++k) rot.Data<float>()[i * 4 + k] = float(q[k] / std::sqrt(norm));
    }
    cloud.SetPointAttr("rot", rot);
    cloud.SetPointAttr("opacity", fill({n, 1}, [&] { return 3.0f * normal(rng); }));
    cloud.SetPointAttr("f_dc", fill({n, 3}, [&] { return normal(rng); }));
    if (degree > 0) {
        cloud.SetPointAttr("f_rest", fill({n, geometry::NumSHRestCoeffs(degree), 3},
                                          [&] { return 0.2f * normal(rng); }));
    }
    return cloud;
}

}  // namespace io
}  // namespace t
}  // namespace open3d
