// gs-bench's streaming run (--stream, docs/streaming.md): the scene's hierarchy written as a
// paged file, then streamed back from that file into a GPU pool of a fixed size while one
// view is rendered after every step, timing the first image and the converged one and
// comparing the converged image with the exact render of the whole scene.
#pragma once

#include <cstdint>
#include <string>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace open3d {
namespace bench {

struct StreamBenchOptions {
    std::string path;              ///< the paged file written, then streamed
    uint64_t gpu_budget = 0;       ///< bytes of the pool's splat storage
    int64_t splat_budget = 0;      ///< nodes per cut; 0: what the pool holds
    int64_t page_capacity = 0;     ///< nodes per page
    int64_t reads_per_step = 0;    ///< pages read per step
    bool compact_storage = false;  ///< the pool at half precision
};

/// Writes `scene` (with `hierarchy`) as pages to options.path, streams it for `camera` into
/// a new Vulkan backend and prints the steps and a summary line starting "stream".
void RunStreamBench(const t::geometry::PointCloud& scene,
                    const t::geometry::SplatHierarchy& hierarchy,
                    const camera::PinholeCamera& camera,
                    const visualization::rendering::RenderConfig& config,
                    const t::geometry::Image& exact, const StreamBenchOptions& options);

}  // namespace bench
}  // namespace open3d
