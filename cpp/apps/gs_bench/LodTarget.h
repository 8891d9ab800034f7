// gs-bench --lod-target-ms: how well RenderConfig::lod_target_ms holds a frame time on a path
// through the run's views (docs/benchmark.md "Level of detail"; docs/lod.md "A budget that holds
// a frame time").
#pragma once

#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace open3d {
namespace bench {

struct LodTargetResult {
    double target_ms = 0.0;
    int frames = 0;                                     ///< timed frames (after the warm-up)
    double median_ms = 0.0, p5_ms = 0.0, p95_ms = 0.0;  ///< GPU time per frame
    double within_10_percent = 0.0;                     ///< fraction of the timed frames
    double min_budget = 0.0, median_budget = 0.0, max_budget = 0.0;  ///< nodes of the cuts
    double wall_ms_per_frame = 0.0;  ///< host wall time per frame, one frame at a time
};

/// Renders `warm_up_frames` frames at the first camera, then `frames_per_view` frames from each
/// camera to the next along a camera path through them (positions on a centripetal
/// Catmull-Rom spline, orientations by squad: camera/CameraPath.h), every frame with
/// `config.lod_target_ms` on `backend`, whose scene is a hierarchy. One camera (a grid's)
/// becomes nine keyframes turning it about its own vertical axis, 20 degrees each way.
LodTargetResult RunLodTargetPath(visualization::rendering::GaussianSplatBackend& backend,
                                 const std::vector<camera::PinholeCamera>& cameras,
                                 const visualization::rendering::RenderConfig& config,
                                 int frames_per_view, int warm_up_frames);

/// The result as gs-bench prints it (one block per scene and resolution).
void PrintLodTargetResult(const char* scene, int width, int height, const LodTargetResult& r);

}  // namespace bench
}  // namespace open3d
