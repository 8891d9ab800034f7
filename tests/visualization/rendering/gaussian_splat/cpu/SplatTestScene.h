// Tiny in-memory splat scenes and a fixed camera for the analytic tests. Expected values
// in the tests are closed-form; these helpers only build inputs and undo float storage.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace tests {

/// SH_C0 typed in from the 3DGS paper's code (not taken from the code under test).
inline constexpr double kTestSH_C0 = 0.28209479177387814;

struct TestSplat {
    Eigen::Vector3d position = Eigen::Vector3d(0, 0, 5);
    Eigen::Vector3d scale = Eigen::Vector3d(0.1, 0.1, 0.1);
    Eigen::Vector4d rot = Eigen::Vector4d(1, 0, 0, 0);       // (w, x, y, z)
    double opacity = 0.5;                                    // after the sigmoid
    Eigen::Vector3d color = Eigen::Vector3d(0.5, 0.5, 0.5);  // degree-0 colour
    std::vector<double> f_rest;                              // [Nc * 3], k-major
};

/// v rounded to float32 and widened back. The volatile keeps GCC 12 -O3 from dropping the
/// rounding (observed: a plain static_cast<float> round trip of an Eigen element vanished).
inline double RoundToFloat(double v) {
    volatile float f = static_cast<float>(v);
    return f;
}

inline float Logit(double p) { return static_cast<float>(std::log(p / (1.0 - p))); }

/// The opacity the renderer sees after the float32 logit round trip.
inline double StoredOpacity(double p) { return 1.0 / (1.0 + std::exp(-double(Logit(p)))); }

/// The degree-0 colour the renderer sees after the float32 f_dc round trip.
inline double StoredColor(double c) {
    return 0.5 + kTestSH_C0 * RoundToFloat((c - 0.5) / kTestSH_C0);
}

inline t::geometry::PointCloud MakeCloud(const std::vector<TestSplat>& splats, int degree = 0) {
    namespace gs = t::geometry::gs_attr;
    const int64_t n = static_cast<int64_t>(splats.size());
    const int nc = (degree + 1) * (degree + 1) - 1;
    std::vector<float> pos, scale, rot, opacity, f_dc, f_rest;
    for (const TestSplat& s : splats) {
        for (int i = 0; i < 3; ++i) {
            pos.push_back(static_cast<float>(s.position[i]));
            scale.push_back(static_cast<float>(s.scale[i]));
            f_dc.push_back(static_cast<float>((s.color[i] - 0.5) / kTestSH_C0));
        }
        for (int i = 0; i < 4; ++i) rot.push_back(static_cast<float>(s.rot[i]));
        opacity.push_back(Logit(s.opacity));
        for (int k = 0; k < nc * 3; ++k) {
            f_rest.push_back(k < static_cast<int>(s.f_rest.size()) ? float(s.f_rest[k]) : 0.f);
        }
    }
    t::geometry::PointCloud cloud(core::Tensor::FromVector(pos, {n, 3}));
    cloud.SetPointAttr(gs::kScale, core::Tensor::FromVector(scale, {n, 3}));
    cloud.SetPointAttr(gs::kRot, core::Tensor::FromVector(rot, {n, 4}));
    cloud.SetPointAttr(gs::kOpacity, core::Tensor::FromVector(opacity, {n, 1}));
    cloud.SetPointAttr(gs::kFDc, core::Tensor::FromVector(f_dc, {n, 3}));
    if (degree > 0) cloud.SetPointAttr(gs::kFRest, core::Tensor::FromVector(f_rest, {n, nc, 3}));
    return cloud;
}

/// Camera at the origin looking along +z (identity extrinsic), fx = fy = 100, principal
/// point on pixel (32, 32) of a 64x64 image so a splat on the axis lands on a pixel.
inline camera::PinholeCamera MakeTestCamera(int width = 64, int height = 64) {
    camera::PinholeCamera cam;
    cam.width = width;
    cam.height = height;
    cam.fx = cam.fy = 100.0;
    cam.cx = cam.cy = 32.0;
    return cam;
}

}  // namespace tests
}  // namespace open3d
