// Random rotations, directions, tensors and splat clouds for the geometry tests, and a compact
// number format for measured errors recorded in the test XML.
#pragma once

#include <Eigen/Geometry>
#include <cstdio>
#include <random>
#include <string>

#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace t {
namespace geometry {

// Measured errors go to the test XML (--gtest_output=xml) in scientific notation.
inline std::string Sci(double value) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.3g", value);
    return text;
}

// Uniform random rotation: a normalised 4D Gaussian is a uniform unit quaternion.
inline Eigen::Matrix3d RandomRotation(std::mt19937& rng) {
    std::normal_distribution<double> normal;
    Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
    return q.normalized().toRotationMatrix();
}

inline Eigen::Vector3d RandomDirection(std::mt19937& rng) {
    std::normal_distribution<double> normal;
    return Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
}

// Float32 values uniform in [lo, hi).
inline core::Tensor RandomTensor(std::mt19937& rng, const core::SizeVector& shape, float lo,
                                 float hi) {
    core::Tensor t(shape, core::Dtype::Float32);
    std::uniform_real_distribution<float> uniform(lo, hi);
    float* p = t.Data<float>();
    for (int64_t i = 0; i < t.NumElements(); ++i) p[i] = uniform(rng);
    return t;
}

// n random splats of the given SH degree with positions in [-5, 5)^3.
inline PointCloud MakeSplatCloud(int64_t n, int degree, uint32_t seed) {
    std::mt19937 rng(seed);
    PointCloud cloud(RandomTensor(rng, {n, 3}, -5.f, 5.f));
    cloud.SetPointAttr(gs_attr::kScale, RandomTensor(rng, {n, 3}, 0.01f, 1.f));
    core::Tensor rot({n, 4}, core::Dtype::Float32);
    std::normal_distribution<double> normal;
    for (int64_t i = 0; i < n; ++i) {
        const Eigen::Vector4d q =
            Eigen::Vector4d(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
        for (int k = 0; k < 4; ++k) rot.Data<float>()[4 * i + k] = static_cast<float>(q[k]);
    }
    cloud.SetPointAttr(gs_attr::kRot, rot);
    cloud.SetPointAttr(gs_attr::kOpacity, RandomTensor(rng, {n, 1}, -3.f, 3.f));
    cloud.SetPointAttr(gs_attr::kFDc, RandomTensor(rng, {n, 3}, -1.f, 1.f));
    if (degree > 0) {
        cloud.SetPointAttr(gs_attr::kFRest,
                           RandomTensor(rng, {n, NumSHRestCoeffs(degree), 3}, -1.f, 1.f));
    }
    return cloud;
}

inline Eigen::Vector3d Position(const PointCloud& cloud, int64_t i) {
    const float* p = cloud.GetPointPositions().Data<float>() + 3 * i;
    return Eigen::Vector3d(p[0], p[1], p[2]);
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
