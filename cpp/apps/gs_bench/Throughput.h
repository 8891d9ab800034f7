// Wall-clock measurements of gs-bench beside the GPU times: frames in flight through the
// Vulkan backend's submission path, with and without readback, and batches of many views
// (docs/benchmark.md "Wall clock").
#pragma once

#include <string>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace open3d {
namespace bench {

/// Wall milliseconds per frame over `frames` single-view frames of `cameras` (cycled), with
/// the backend's frames in flight kept full: frame k + depth is submitted once frame k is
/// collected.
double PipelinedMsPerFrame(visualization::rendering::vulkan::GaussianSplatVulkanBackend& backend,
                           const std::vector<camera::PinholeCamera>& cameras,
                           const visualization::rendering::RenderConfig& config,
                           const visualization::rendering::BatchOptions& options, int frames);

struct BatchThroughput {
    double views_per_second = 0.0;
    double gpu_ms_per_view = 0.0;  ///< the batches' GPU time over their views
    int submissions_per_batch = 0;
};

/// RenderBatch of `batch` views (`cameras` repeated) `repeats` times after warm-up batches
/// for `warm_up_seconds` (at least one: it records and allocates).
BatchThroughput MeasureBatch(visualization::rendering::vulkan::GaussianSplatVulkanBackend& backend,
                             const std::vector<camera::PinholeCamera>& cameras,
                             const visualization::rendering::RenderConfig& config,
                             const visualization::rendering::BatchOptions& options, int batch,
                             int repeats, double warm_up_seconds);

/// GB/s (1e9 bytes) of one device-to-host copy of `bytes` repeated `repeats` times with
/// nothing else running: from a device buffer into page-aligned host memory the device
/// imports (the path of BatchOptions::color_memory), on the transfer queue where the device
/// has one. 0 where host memory cannot be imported. The ceiling of every readback.
double MeasureDeviceToHostGBs(const visualization::rendering::vulkan::VulkanContext& context,
                              uint64_t bytes, int repeats);

/// "current/max" SM clock in MHz from nvidia-smi, or "" where it is not available.
std::string ReadGpuClockMHz();

}  // namespace bench
}  // namespace open3d
