#include "open3d/visualization/rendering/gaussian_splat/cpu/LodCut.h"

#include <algorithm>
#include <cmath>

#include "open3d/core/Exception.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

namespace {

// Whether the sphere lies wholly outside a side plane of an image axis spanning [lo, hi] in
// x / z, widened by 15% of the span and 2 px (as t::geometry's cut and the shader).
bool OutsideAxis(double x, double z, double lo, double hi, double focal, double radius) {
    const double margin = 0.15 * (hi - lo) + 2.0 / focal;
    lo -= margin;
    hi += margin;
    return (x - lo * z) / std::sqrt(1.0 + lo * lo) < -radius ||
           (hi * z - x) / std::sqrt(1.0 + hi * hi) < -radius;
}

}  // namespace

uint32_t LodSizeBucket(const camera::PinholeCamera& camera, const double center[3], double radius) {
    const Eigen::Vector3d c =
        camera.GetRotation() * Eigen::Vector3d(center[0], center[1], center[2]) +
        camera.GetTranslation();
    if (c.z() + radius <= 0.0) return 0u;
    if (OutsideAxis(c.x(), c.z(), (-0.5 - camera.cx) / camera.fx,
                    (camera.width - 0.5 - camera.cx) / camera.fx, camera.fx, radius) ||
        OutsideAxis(c.y(), c.z(), (-0.5 - camera.cy) / camera.fy,
                    (camera.height - 0.5 - camera.cy) / camera.fy, camera.fy, radius)) {
        return 0u;
    }
    const double size =
        std::max(camera.fx, camera.fy) * radius / std::max(c.z(), 1e-3 * radius + 1e-30);
    const double b =
        std::floor((std::log2(size) + shader::kLodLog2Offset) * shader::kLodBucketsPerOctave);
    if (!(b >= 0.0)) return 1u;
    return static_cast<uint32_t>(std::min(b, double(shader::kLodBuckets - 2u))) + 1u;
}

LodCutResult CutLikeGpu(const t::geometry::SplatHierarchy& hierarchy,
                        const camera::PinholeCamera& camera, uint64_t budget) {
    const int64_t n = hierarchy.num_leaves;
    const int64_t k_inner = hierarchy.NumInner();
    std::vector<int64_t> parent(size_t(n + k_inner), -1);
    for (int64_t k = 0; k < k_inner; ++k) {
        for (int64_t c = hierarchy.child_offsets[size_t(k)];
             c < hierarchy.child_offsets[size_t(k) + 1]; ++c) {
            parent[size_t(hierarchy.children[size_t(c)])] = n + k;
        }
    }
    // Own buckets, then the smallest on the path to the root (parents come later in id
    // order, so walking from the root down fills every node after its parent).
    std::vector<uint32_t> bucket(size_t(k_inner), 0u);
    if (k_inner > 0) {
        const t::geometry::GaussianSplatArrays inner = hierarchy.inner.GetGaussianSplatArrays();
        for (int64_t k = 0; k < k_inner; ++k) {
            const float* p = inner.positions + 3 * k;
            const float* s = inner.scale + 3 * k;
            const double center[3] = {p[0], p[1], p[2]};
            const double radius = 3.0 * std::max({std::abs(s[0]), std::abs(s[1]), std::abs(s[2])});
            bucket[size_t(k)] = LodSizeBucket(camera, center, radius);
        }
        for (int64_t k = k_inner - 1; k >= 0; --k) {
            const int64_t up = parent[size_t(n + k)];
            if (up >= 0) bucket[size_t(k)] = std::min(bucket[size_t(k)], bucket[size_t(up - n)]);
        }
    }
    std::vector<uint64_t> histogram(shader::kLodBuckets, 0u);
    uint64_t total = 0;
    for (int64_t k = 0; k < k_inner; ++k) {
        const uint64_t adds = uint64_t(hierarchy.child_offsets[size_t(k) + 1] -
                                       hierarchy.child_offsets[size_t(k)] - 1);
        histogram[bucket[size_t(k)]] += adds;
        total += adds;
    }
    const uint64_t limit = budget == 0 ? UINT64_MAX : std::max<uint64_t>(budget, 1);
    LodCutResult result;
    if (total < limit) {
        result.threshold = shader::kLodOpenAll;
    } else {
        uint64_t above = 0;  // what opening every bucket above t adds
        uint32_t t = shader::kLodBuckets - 1u;
        while (t > 0 && above + histogram[t] + 1 <= limit) {
            above += histogram[t];
            --t;
        }
        result.threshold = t;
    }
    const auto opens = [&](int64_t node) {
        return node >= n && (result.threshold == shader::kLodOpenAll ||
                             bucket[size_t(node - n)] > result.threshold);
    };
    for (int64_t node = 0; node < n + k_inner; ++node) {
        const int64_t up = parent[size_t(node)];
        if ((up < 0 || opens(up)) && !opens(node)) result.nodes.push_back(node);
    }
    return result;
}

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
