// gs-bench's level-of-detail rows (docs/benchmark.md "Level of detail"): the --lod-budgets
// list, and one view's cut of a scene's hierarchy (t/geometry/SplatHierarchy.h) as the cloud
// the backend renders in place of the scene.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"

namespace open3d {
namespace bench {

/// Splat budgets from "500k,1M,2.5M,3000" (k = 1e3, M = 1e6; each >= 1, whole numbers of
/// splats). Throws core::Open3DError naming the item that is not one.
std::vector<int64_t> ParseBudgets(const std::string& text);

/// The budget as --lod-budgets would spell it: "500k", "12.5k", "1M", "2.5M", "3001".
std::string BudgetLabel(int64_t budget);

/// A view's cut: the cloud of its nodes, how many, and the CPU time the cut and the
/// extraction took: the rows of backends without the GPU cut (docs/lod.md).
struct LodCut {
    t::geometry::PointCloud cloud;
    int64_t nodes = 0;
    double cut_ms = 0.0;
};

/// The exact render of `camera`'s view at s x s times its pixels, box-filtered back to its
/// size (--lod-supersample): drawn as s x s tiles of the camera's own size (SupersampledView
/// shifted by whole tiles), so no frame holds more tile entries than the view does at its own
/// size. Throws core::Open3DError when s does not divide the size or a tile's frame dropped
/// entries (its picture would be wrong).
t::geometry::Image FilteredReference(visualization::rendering::GaussianSplatBackend& backend,
                                     const camera::PinholeCamera& camera, int s,
                                     const visualization::rendering::RenderConfig& config);

/// The cut of `hierarchy` (built from `source`) for `camera` under `budget` splats.
LodCut CutForView(const t::geometry::SplatHierarchy& hierarchy,
                  const t::geometry::PointCloud& source, const camera::PinholeCamera& camera,
                  int64_t budget);

}  // namespace bench
}  // namespace open3d
