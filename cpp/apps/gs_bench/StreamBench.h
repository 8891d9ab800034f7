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

/// What a streaming run measured (gs-bench --json's "stream" row).
struct StreamBenchResult {
    int64_t file_pages = 0, pool_pages = 0, pool_splats = 0;
    double bytes_per_splat = 0;
    bool compact_storage = false;
    double pool_ready_ms = 0;  ///< after the load started
    double first_image_ms = 0, first_image_psnr_db = 0;
    double converged_ms = 0;  ///< nothing more wanted, or the pool full
    int steps = 0;
    int64_t pages_read = 0, evictions = 0, cut_nodes = 0;
    uint64_t bytes_read = 0;
    bool pool_full = false;  ///< converged because no slot was left
    double psnr_db = 0, max_abs_error = 0, fraction_over_1_255 = 0;  ///< converged image
};

/// Writes `scene` (with `hierarchy`) as pages to options.path, streams it for `camera` into
/// a new Vulkan backend and prints the steps and a summary line starting "stream".
StreamBenchResult RunStreamBench(const t::geometry::PointCloud& scene,
                                 const t::geometry::SplatHierarchy& hierarchy,
                                 const camera::PinholeCamera& camera,
                                 const visualization::rendering::RenderConfig& config,
                                 const t::geometry::Image& exact,
                                 const StreamBenchOptions& options);

}  // namespace bench
}  // namespace open3d
