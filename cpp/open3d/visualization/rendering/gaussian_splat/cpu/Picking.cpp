#include "open3d/visualization/rendering/gaussian_splat/cpu/Picking.h"

#include <Eigen/Dense>

#include <cmath>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/PixelBlend.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

PickResult PickPixel(const t::geometry::PointCloud& cloud, const camera::PinholeCamera& camera,
                     const RenderConfig& config, int x, int y) {
    camera.Validate();
    if (x < 0 || y < 0 || x >= camera.width || y >= camera.height) {
        core::ThrowError("PickPixel: pixel ({}, {}) is outside the {}x{} image", x, y, camera.width,
                         camera.height);
    }
    const std::vector<ProjectedSplat> splats = ProjectSplats(cloud, camera, config);
    const TileGrid grid = TileGrid::ForImage(camera.width, camera.height);
    const TileLists lists = BuildTileLists(splats, grid, config);
    const int64_t tile = int64_t(y / kTileSize) * grid.tiles_x + x / kTileSize;
    const std::vector<TileSplat> local = TileSplats(splats, lists, tile);
    PickResult pick;
    double weighted_depth = 0.0;
    const double transmittance =
        BlendPixel(local, x, y, HUGE_VAL, [&](const TileSplat& s, double w, double t_after) {
            if (w > pick.weight) {
                pick.weight = w;
                pick.splat = s.index;
            }
            weighted_depth += s.depth * w;
            if (pick.median_depth == 0.0 && 1.0 - t_after >= 0.5) pick.median_depth = s.depth;
        });
    pick.alpha = 1.0 - transmittance;
    pick.hit = pick.splat >= 0;
    if (!pick.hit) return pick;
    pick.expected_depth = weighted_depth / pick.alpha;
    // The ray through the pixel's centre, at view z = the expected depth.
    pick.point = camera.PixelToWorld(x, y, pick.expected_depth);
    return pick;
}

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
