#include "LodTarget.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>

#include <Eigen/Geometry>

#include "open3d/camera/CameraPath.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Percentile.h"
#include "open3d/core/Timer.h"

namespace open3d {
namespace bench {

LodTargetResult RunLodTargetPath(visualization::rendering::GaussianSplatBackend& backend,
                                 const std::vector<camera::PinholeCamera>& cameras,
                                 const visualization::rendering::RenderConfig& config,
                                 int frames_per_view, int warm_up_frames) {
    if (cameras.empty()) core::ThrowError("--lod-target-ms: no view to render");
    // One second per keyframe at frames_per_view frames per second.
    std::vector<camera::CameraKeyframe> keyframes;
    for (size_t i = 0; i < cameras.size(); ++i) keyframes.push_back({double(i), cameras[i]});
    if (cameras.size() == 1) {
        // One view (gs-bench --grid): the camera turns about its own vertical axis, 20 degrees
        // either way and back, so the path still sees more and less of the scene.
        keyframes.clear();
        const double degrees[] = {0, -10, -20, -10, 0, 10, 20, 10, 0};
        for (size_t i = 0; i < std::size(degrees); ++i) {
            camera::PinholeCamera turned = cameras[0];
            Eigen::Matrix4d turn = Eigen::Matrix4d::Identity();
            turn.topLeftCorner<3, 3>() =
                Eigen::AngleAxisd(degrees[i] * M_PI / 180.0, Eigen::Vector3d::UnitY())
                    .toRotationMatrix();
            turned.world_to_camera = turn * cameras[0].world_to_camera;
            keyframes.push_back({double(i), turned});
        }
    }
    const std::vector<camera::PinholeCamera> path =
        camera::CameraPath(keyframes).Frames(double(frames_per_view));
    for (int f = 0; f < warm_up_frames; ++f) backend.Render(cameras[0], config);
    std::vector<double> ms, budgets;
    const auto start = std::chrono::steady_clock::now();
    for (const camera::PinholeCamera& camera : path) {
        const visualization::rendering::RenderStats s = backend.Render(camera, config).stats;
        ms.push_back(s.gpu_project_ms + s.gpu_sort_ms + s.gpu_composite_ms);
        budgets.push_back(static_cast<double>(s.lod_cut_nodes));
    }
    LodTargetResult r;
    r.wall_ms_per_frame = core::MillisecondsSince(start) / double(path.size());
    r.target_ms = config.lod_target_ms;
    r.frames = static_cast<int>(path.size());
    r.median_ms = core::Percentile(ms, 0.5);
    r.p5_ms = core::Percentile(ms, 0.05);
    r.p95_ms = core::Percentile(ms, 0.95);
    r.within_10_percent =
        double(std::count_if(ms.begin(), ms.end(),
                             [&](double t) { return std::abs(t / r.target_ms - 1.0) <= 0.1; })) /
        double(ms.size());
    r.min_budget = core::Percentile(budgets, 0.0);
    r.median_budget = core::Percentile(budgets, 0.5);
    r.max_budget = core::Percentile(budgets, 1.0);
    return r;
}

void PrintLodTargetResult(const char* scene, int width, int height, const LodTargetResult& r) {
    std::printf(
        "%s %dx%d, lod target %.3f ms: %d frames along the views' path, GPU ms median %.3f "
        "(5%% %.3f, 95%% %.3f), %.1f%% of the frames within 10%% of the target, cut of %.0f / "
        "%.0f / %.0f nodes (min / median / max), wall %.3f ms per frame\n",
        scene, width, height, r.target_ms, r.frames, r.median_ms, r.p5_ms, r.p95_ms,
        100.0 * r.within_10_percent, r.min_budget, r.median_budget, r.max_budget,
        r.wall_ms_per_frame);
    std::fflush(stdout);
}

}  // namespace bench
}  // namespace open3d
