#include "open3d/t/geometry/PointCloudStatistics.h"

#include <algorithm>
#include <vector>

namespace open3d {
namespace t {
namespace geometry {

Eigen::Vector3d ComputeMedianCenter(const PointCloud& cloud) {
    const int64_t n = cloud.NumPoints();
    if (n == 0) return Eigen::Vector3d::Zero();
    const float* p = cloud.GetPointPositions().Data<float>();  // [N, 3]
    Eigen::Vector3d c;
    std::vector<float> axis(n);
    for (int a = 0; a < 3; ++a) {
        for (int64_t i = 0; i < n; ++i) axis[i] = p[3 * i + a];
        std::nth_element(axis.begin(), axis.begin() + n / 2, axis.end());
        c[a] = axis[n / 2];
    }
    return c;
}

double ComputeDistanceQuantile(const PointCloud& cloud, const Eigen::Vector3d& center,
                               double fraction) {
    const int64_t n = cloud.NumPoints();
    if (n == 0) return 1.0;
    const float* p = cloud.GetPointPositions().Data<float>();  // [N, 3]
    std::vector<double> d(n);
    for (int64_t i = 0; i < n; ++i) {
        d[i] = (Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]) - center).norm();
    }
    const int64_t k = std::clamp<int64_t>(static_cast<int64_t>(fraction * n), 0, n - 1);
    std::nth_element(d.begin(), d.begin() + k, d.end());
    return std::max(1e-3, d[k]);
}

}  // namespace geometry
}  // namespace t
}  // namespace open3d
