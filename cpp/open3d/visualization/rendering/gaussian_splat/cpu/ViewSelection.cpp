#include "open3d/visualization/rendering/gaussian_splat/cpu/ViewSelection.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/PixelBlend.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

std::vector<Eigen::Vector2d> RectanglePolygon(double x0, double y0, double x1, double y1) {
    const double lx = std::min(x0, x1), hx = std::max(x0, x1);
    const double ly = std::min(y0, y1), hy = std::max(y0, y1);
    return {{lx, ly}, {hx, ly}, {hx, hy}, {lx, hy}};
}

bool PolygonContains(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& p) {
    bool inside = false;
    const size_t n = polygon.size();
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        const Eigen::Vector2d& a = polygon[i];
        const Eigen::Vector2d& b = polygon[j];
        // On an edge counts as inside (closed), as boxes are.
        const Eigen::Vector2d ab = b - a, ap = p - a;
        const double cross = ab.x() * ap.y() - ab.y() * ap.x();
        if (cross == 0.0 && ap.dot(ab) >= 0.0 && ap.dot(ab) <= ab.squaredNorm()) return true;
        if ((a.y() > p.y()) != (b.y() > p.y()) &&
            p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
            inside = !inside;
        }
    }
    return inside;
}

std::vector<int64_t> SelectSplatsInView(const t::geometry::PointCloud& cloud,
                                        const camera::PinholeCamera& camera,
                                        const RenderConfig& config,
                                        const std::vector<Eigen::Vector2d>& polygon,
                                        bool include_occluded) {
    if (polygon.size() < 3) {
        core::ThrowError("SelectSplatsInView: a region needs at least 3 vertices, got {}",
                         polygon.size());
    }
    for (const Eigen::Vector2d& v : polygon) {
        if (!v.allFinite()) core::ThrowError("SelectSplatsInView: a vertex is not finite");
    }
    camera.Validate();
    const std::vector<ProjectedSplat> splats = ProjectSplats(cloud, camera, config);
    std::vector<uint8_t> selected(splats.size(), 0);
    for (size_t i = 0; i < splats.size(); ++i) {
        selected[i] = splats[i].IsVisible() &&
                      PolygonContains(polygon, Eigen::Vector2d(splats[i].x, splats[i].y));
    }
    if (!include_occluded) {
        // Which of them the view shows inside the region: composite its pixels and keep the
        // splats that blend with a weight of at least 1/255 somewhere.
        const TileGrid grid = TileGrid::ForImage(camera.width, camera.height);
        const TileLists lists = BuildTileLists(splats, grid, config);
        Eigen::Vector2d lo = polygon.front(), hi = polygon.front();
        for (const Eigen::Vector2d& v : polygon) {
            lo = lo.cwiseMin(v);
            hi = hi.cwiseMax(v);
        }
        std::vector<std::atomic<uint8_t>> shown(splats.size());
        for (auto& s : shown) s.store(0, std::memory_order_relaxed);
        core::ParallelFor(
            grid.NumTiles(),
            [&](int64_t tile) {
                const int tx = int(tile % grid.tiles_x), ty = int(tile / grid.tiles_x);
                const int x0 = std::max(tx * kTileSize, int(std::ceil(lo.x())));
                const int x1 = std::min((tx + 1) * kTileSize - 1, int(std::floor(hi.x())));
                const int y0 = std::max(ty * kTileSize, int(std::ceil(lo.y())));
                const int y1 = std::min((ty + 1) * kTileSize - 1, int(std::floor(hi.y())));
                if (x0 > x1 || y0 > y1) return;
                const std::vector<TileSplat> local = TileSplats(splats, lists, tile);
                for (int py = std::max(y0, 0); py <= std::min(y1, camera.height - 1); ++py) {
                    for (int px = std::max(x0, 0); px <= std::min(x1, camera.width - 1); ++px) {
                        if (!PolygonContains(polygon, Eigen::Vector2d(px, py))) continue;
                        BlendPixel(local, px, py, HUGE_VAL,
                                   [&](const TileSplat& s, double weight, double) {
                                       if (weight >= kMinAlpha) {
                                           shown[s.index].store(1, std::memory_order_relaxed);
                                       }
                                   });
                    }
                }
            },
            1);
        for (size_t i = 0; i < splats.size(); ++i) selected[i] = selected[i] && shown[i].load();
    }
    std::vector<int64_t> out;
    for (size_t i = 0; i < selected.size(); ++i) {
        if (selected[i]) out.push_back(int64_t(i));
    }
    return out;
}

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
