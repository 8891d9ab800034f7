#include "BenchScenes.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"

namespace open3d {
namespace bench {

camera::PinholeCamera ScaleViewTo(const camera::PinholeCamera& view, int width, int height) {
    camera::PinholeCamera cam = view;
    const double scale = static_cast<double>(height) / view.height;
    cam.fx = view.fx * scale;
    cam.fy = view.fx * scale;  // fx = fy = fx_json * H / H_json
    cam.width = width;
    cam.height = height;
    cam.cx = (width - 1) / 2.0;
    cam.cy = (height - 1) / 2.0;
    return cam;
}

camera::PinholeCamera SupersampledView(const camera::PinholeCamera& view, int s) {
    camera::PinholeCamera cam = view;
    cam.width = view.width * s;
    cam.height = view.height * s;
    cam.fx = view.fx * s;
    cam.fy = view.fy * s;
    cam.cx = s * (view.cx + 0.5) - 0.5;
    cam.cy = s * (view.cy + 0.5) - 0.5;
    return cam;
}

t::geometry::PointCloud FirstSplats(const t::geometry::PointCloud& cloud, int64_t n) {
    const int64_t total = cloud.NumPoints();
    if (n < 1 || n > total) {
        core::ThrowError("--first {}: the scene has {} splats", n, total);
    }
    t::geometry::PointCloud out;
    for (const std::string& name : cloud.GetPointAttrNames()) {
        const core::Tensor& attr = cloud.GetPointAttr(name);
        core::SizeVector shape = attr.GetShape();
        shape.at(0) = n;
        core::Tensor head(shape, attr.GetDtype());
        const auto* src = static_cast<const uint8_t*>(attr.RawData());
        std::copy(src, src + head.NumBytes(), static_cast<uint8_t*>(head.RawData()));
        out.SetPointAttr(name, std::move(head));
    }
    return out;
}

t::geometry::PointCloud MakeGridScene(const t::geometry::PointCloud& tile, int k, double* spacing) {
    if (k < 1) core::ThrowError("--grid needs K >= 1, got {}", k);
    tile.ValidateGaussianSplat();
    const int64_t n = tile.NumPoints();
    {
        // Checked before the copies are made (--grid 64 once grew past 12 GB and on).
        const uint64_t per_copy = std::max<uint64_t>(tile.NumBytes(), 1);
        const uint64_t available = core::AvailableHostMemory();
        const int fits = int(std::sqrt(double(available / per_copy)));
        core::RequireHostMemory(
            per_copy * uint64_t(k) * uint64_t(k),
            fmt::format("--grid {}: {} x {} copies of {} splats ({} splats)", k, k, k, n,
                        int64_t(k) * k * n),
            fits >= 1 ? fmt::format("--grid {} fits", fits) : "not even one copy fits");
    }
    const float* p = tile.GetPointPositions().Data<float>();
    double lo[3], hi[3];
    for (int c = 0; c < 3; ++c) {
        lo[c] = std::numeric_limits<double>::infinity();
        hi[c] = -std::numeric_limits<double>::infinity();
    }
    for (int64_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
            lo[c] = std::min(lo[c], double(p[i * 3 + c]));
            hi[c] = std::max(hi[c], double(p[i * 3 + c]));
        }
    }
    const double s = 1.1 * std::max(hi[0] - lo[0], hi[2] - lo[2]);
    if (spacing) *spacing = s;

    t::geometry::PointCloud grid;
    const int64_t copies = static_cast<int64_t>(k) * k;
    for (const std::string& name : tile.GetPointAttrNames()) {
        const core::Tensor& src = tile.GetPointAttr(name);
        core::SizeVector shape = src.GetShape();
        shape[0] *= copies;
        core::Tensor dst = core::Tensor::Empty(shape, src.GetDtype());
        const int64_t bytes = src.NumBytes();
        auto* out = static_cast<uint8_t*>(dst.RawData());
        for (int64_t c = 0; c < copies; ++c) {
            std::copy_n(static_cast<const uint8_t*>(src.RawData()), bytes, out + c * bytes);
        }
        if (name == t::geometry::gs_attr::kPositions) {
            float* q = dst.Data<float>();
            for (int gz = 0; gz < k; ++gz) {
                for (int gx = 0; gx < k; ++gx) {
                    // Offsets -(k-1)/2 .. (k-1)/2 times s: the grid is centred on the tile.
                    const double ox = (gx - (k - 1) / 2.0) * s;
                    const double oz = (gz - (k - 1) / 2.0) * s;
                    float* block = q + (static_cast<int64_t>(gz) * k + gx) * n * 3;
                    for (int64_t i = 0; i < n; ++i) {
                        block[i * 3 + 0] = static_cast<float>(block[i * 3 + 0] + ox);
                        block[i * 3 + 2] = static_cast<float>(block[i * 3 + 2] + oz);
                    }
                }
            }
        }
        if (name == t::geometry::gs_attr::kPositions) {
            grid.SetPointPositions(std::move(dst));
        } else {
            grid.SetPointAttr(name, std::move(dst));
        }
    }
    return grid;
}

camera::PinholeCamera MakeGridCamera(const t::geometry::PointCloud& tile,
                                     const camera::PinholeCamera& view, int k, double spacing,
                                     int width, int height) {
    const int64_t n = tile.NumPoints();
    const float* p = tile.GetPointPositions().Data<float>();
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int64_t i = 0; i < n; ++i) mean += Eigen::Vector3d(p[i * 3], p[i * 3 + 1], p[i * 3 + 2]);
    mean /= static_cast<double>(std::max<int64_t>(n, 1));

    camera::PinholeCamera cam;
    cam.width = width;
    cam.height = height;
    cam.fx = cam.fy = 1400.0 * height / 1080.0;
    cam.cx = (width - 1) / 2.0;
    cam.cy = (height - 1) / 2.0;
    // cameras.json rotation is camera-to-world: its third column is the camera's forward.
    const Eigen::Matrix3d world_to_camera = view.GetRotation();
    const Eigen::Vector3d forward = world_to_camera.transpose().col(2);
    const double d = 1.05 * (k * spacing / 2.0) / (width / (2.0 * cam.fx));
    const Eigen::Vector3d center = mean - forward * d;
    cam.world_to_camera.setIdentity();
    cam.world_to_camera.topLeftCorner<3, 3>() = world_to_camera;
    cam.world_to_camera.topRightCorner<3, 1>() = -world_to_camera * center;
    return cam;
}

}  // namespace bench
}  // namespace open3d
