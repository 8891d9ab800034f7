// Random rotations and directions for the geometry tests, and a compact number format for
// measured errors recorded in the test XML.
#pragma once

#include <Eigen/Geometry>
#include <cstdio>
#include <random>
#include <string>

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

}  // namespace geometry
}  // namespace t
}  // namespace open3d
