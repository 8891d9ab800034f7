// Scenes and cameras of gs-bench, defined exactly (issue 9) so results compare across tools.
#pragma once

#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"

namespace open3d {
namespace bench {

/// A cameras.json view moved to another image size the benchmark way: fx = fy =
/// fx_json * H / H_json (the vertical field of view is kept), principal point at the image
/// centre ((W - 1) / 2, (H - 1) / 2). Unlike Resized(), the horizontal extent follows W.
camera::PinholeCamera ScaleViewTo(const camera::PinholeCamera& view, int width, int height);

/// `view` with s x s pixels in place of each of its pixels: focal lengths times s and the
/// principal point where pixel (x, y)'s block of s x s is pixel (x, y) of `view`
/// (c' = s (c + 0.5) - 0.5). Image::BoxDownsample(s) of its render is back at `view`'s size.
camera::PinholeCamera SupersampledView(const camera::PinholeCamera& view, int s);

/// The first `n` splats of `cloud` (every attribute's first n rows): a scene of one or a
/// thousand splats times what a frame costs when there is almost nothing to draw.
t::geometry::PointCloud FirstSplats(const t::geometry::PointCloud& cloud, int64_t n);

/// K x K copies of `tile` (e.g. playbot_125k) offset by multiples of
/// s = 1.1 * max(extent_x, extent_z) of its bounding box along x and z, centred on it.
/// Returns s through `spacing`.
t::geometry::PointCloud MakeGridScene(const t::geometry::PointCloud& tile, int k,
                                      double* spacing = nullptr);

/// The grid camera: rotation of `view` (cameras.json view 0 of playbot), fx = fy =
/// 1400 * H / 1080, principal point at the centre, positioned at mean(tile positions) -
/// forward * d with forward = the rotation's third column (camera z in world space) and
/// d = 1.05 * (k s / 2) / (W / (2 fx)).
camera::PinholeCamera MakeGridCamera(const t::geometry::PointCloud& tile,
                                     const camera::PinholeCamera& view, int k, double spacing,
                                     int width, int height);

}  // namespace bench
}  // namespace open3d
