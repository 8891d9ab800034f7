// gs-bench: timed frames (medians per pass), the configuration every timed row starts from,
// frames in flight, and the rows' per-view columns.
#include "GsBenchRows.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>
#include "BenchScenes.h"
#include "LodBudgets.h"
#include "StreamBench.h"
#include "Throughput.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Percentile.h"
#include "open3d/core/Timer.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/OutputFiles.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamSession.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace open3d {
namespace bench {

double Median(std::vector<double> v) {
    return v.empty() ? 0.0 : core::Percentile(std::move(v), 0.5);
}

// Medians of the host_* fields of `frames`.
rendering::RenderStats MedianHost(const std::vector<rendering::RenderStats>& frames) {
    std::vector<double> record, submit, wait, readback;
    for (const auto& s : frames) {
        record.push_back(s.host_record_ms);
        submit.push_back(s.host_submit_ms);
        wait.push_back(s.host_wait_ms);
        readback.push_back(s.host_readback_ms);
    }
    rendering::RenderStats m;
    m.host_record_ms = Median(record);
    m.host_submit_ms = Median(submit);
    m.host_wait_ms = Median(wait);
    m.host_readback_ms = Median(readback);
    return m;
}

// Times `frames` frames (geometry stage + composite stage, no readback) after warm-up frames
// (`warm_up_seconds` of them, or with a negative value until the GPU time settles), and returns the
// median of each GPU pass and of the CPU wall time per frame. Frames follow each other with only
// the submit/fence gap, so a GPU that lowers its clocks when idle (every NVIDIA board does) is
// timed at full clock: with a readback between frames the H100 ran the same depth sort 2.5-5x
// slower. (Run loops time everything before the CPU references: see Run.)
TimedFrames RunTimedFrames(rendering::GaussianSplatBackend& backend,
                           const camera::PinholeCamera& camera,
                           const rendering::RenderConfig& config, int frames,
                           const std::string& depth, double warm_up_seconds) {
    constexpr double kWarmUpSeconds = 1.0;
    rendering::CompositeInputs no_readback;
    no_readback.read_back = false;
    no_readback.expected_depth = depth == "expected" || depth == "both";
    no_readback.median_depth = depth == "median" || depth == "both";
    rendering::RenderOutput out;
    double wall_ms = 0.0;  // of the last frame
    const auto frame = [&]() {
        const auto start = std::chrono::steady_clock::now();
        backend.RenderGeometryStage(camera, config);
        backend.RenderCompositeStage(out, no_readback);
        wall_ms = core::MillisecondsSince(start);
        return out.stats;
    };
    // Warm up until the GPU time stops falling: windows of 20 frames until a window's
    // median is no longer 2% below the previous one (at least kWarmUpSeconds, at most 10 s).
    // After seconds of CPU work the H100 needed more than 1 s of these frames (its duty
    // cycle is only ~25%) to reach full clocks: a fixed 1 s warm-up left rows 1.6x slow.
    const auto warm_start = std::chrono::steady_clock::now();
    double previous = INFINITY;
    while (warm_up_seconds >= 0.0 && core::MillisecondsSince(warm_start) < 1000.0 * warm_up_seconds)
        frame();
    while (warm_up_seconds < 0.0 && core::MillisecondsSince(warm_start) < 10000.0) {
        std::vector<double> window;
        for (int i = 0; i < 20; ++i) {
            const rendering::RenderStats s = frame();
            window.push_back(s.gpu_project_ms + s.gpu_sort_ms + s.gpu_composite_ms);
        }
        const double median = Median(window);
        if (core::MillisecondsSince(warm_start) >= 1000.0 * kWarmUpSeconds &&
            median > 0.98 * previous) {
            break;
        }
        previous = std::min(previous, median);
    }
    std::vector<double> project, sort, composite, depth_sort, scan_emit, tile_sort, lod_cut,
        lod_list, wall;
    std::vector<rendering::RenderStats> stage_stats;
    for (int i = 0; i < frames; ++i) {
        const rendering::RenderStats s = frame();
        stage_stats.push_back(s);
        project.push_back(s.gpu_project_ms);
        sort.push_back(s.gpu_sort_ms);
        composite.push_back(s.gpu_composite_ms);
        depth_sort.push_back(s.gpu_depth_sort_ms);
        scan_emit.push_back(s.gpu_scan_emit_ms);
        tile_sort.push_back(s.gpu_tile_sort_ms);
        lod_cut.push_back(s.gpu_lod_cut_ms);
        lod_list.push_back(s.gpu_lod_list_ms);
        wall.push_back(wall_ms);
    }
    TimedFrames m;
    m.gpu = out.stats;
    m.gpu.gpu_project_ms = Median(project);
    m.gpu.gpu_sort_ms = Median(sort);
    m.gpu.gpu_composite_ms = Median(composite);
    m.gpu.gpu_depth_sort_ms = Median(depth_sort);
    m.gpu.gpu_scan_emit_ms = Median(scan_emit);
    m.gpu.gpu_tile_sort_ms = Median(tile_sort);
    m.gpu.gpu_lod_cut_ms = Median(lod_cut);
    m.gpu.gpu_lod_list_ms = Median(lod_list);
    m.cpu_frame_ms = Median(wall);
    m.stage_host = MedianHost(stage_stats);
    // The submission path: both stages in one submission (a recording re-submitted), waited for.
    std::vector<double> one_submission, passes, job;
    std::vector<rendering::RenderStats> submission_stats;
    auto* vulkan = dynamic_cast<rendering::vulkan::GaussianSplatVulkanBackend*>(&backend);
    for (int i = 0; i < frames + 2; ++i) {
        const auto start = std::chrono::steady_clock::now();
        const rendering::RenderOutput o = backend.Render(camera, config, no_readback);
        if (i < 2) continue;  // each frame slot records once
        one_submission.push_back(core::MillisecondsSince(start));
        submission_stats.push_back(o.stats);
        passes.push_back(o.stats.gpu_project_ms + o.stats.gpu_sort_ms + o.stats.gpu_composite_ms);
        if (vulkan != nullptr) job.push_back(vulkan->GetLastBatchStats().gpu_ms);
    }
    m.frame_ms = Median(one_submission);
    m.frame_gpu_ms = Median(passes);
    m.frame_job_gpu_ms = Median(job);
    m.frame_host = MedianHost(submission_stats);
    if (!submission_stats.empty()) {  // the same recording every frame: its counts
        m.frame_host.dispatches = submission_stats.back().dispatches;
        m.frame_host.dependent_dispatches = submission_stats.back().dependent_dispatches;
    }
    return m;
}

// The configuration every timed row starts from: geometry re-run per frame, and the entry
// cap of --max-tile-entries where given.
rendering::RenderConfig TimedConfig(const Options& opt) {
    rendering::RenderConfig config;
    config.reuse_geometry = false;
    if (opt.max_tile_entries > 0) config.max_tile_entries_total = opt.max_tile_entries;
    return config;
}

// Wall ms per frame with frames in flight over `cams`, colour only, without and with the
// RGBA32F readback, each over max(--wall-frames, --repeat) frames.
std::pair<double, double> PipelinedMs(const Options& opt,
                                      rendering::vulkan::GaussianSplatVulkanBackend& vulkan,
                                      const std::vector<camera::PinholeCamera>& cams,
                                      const rendering::RenderConfig& config) {
    rendering::BatchOptions colour;  // colour only, as the timed frames
    const int frames = std::max(opt.wall_frames, opt.repeat);
    colour.read_back = false;
    const double no_readback = bench::PipelinedMsPerFrame(vulkan, cams, config, colour, frames);
    colour.read_back = true;
    return {no_readback, bench::PipelinedMsPerFrame(vulkan, cams, config, colour, frames)};
}

// Adds one view's timed frames and its full frame's counts to `row`, as the mean over
// `num_views` views.
void AddView(Row& row, const TimedFrames& timed, const rendering::RenderStats& full,
             size_t num_views) {
    const rendering::RenderStats& med = timed.gpu;
    const double n = static_cast<double>(num_views);
    row.project_ms += med.gpu_project_ms / n;
    row.sort_ms += med.gpu_sort_ms / n;
    row.composite_ms += med.gpu_composite_ms / n;
    row.depth_sort_ms += med.gpu_depth_sort_ms / n;
    row.scan_emit_ms += med.gpu_scan_emit_ms / n;
    row.tile_sort_ms += med.gpu_tile_sort_ms / n;
    row.lod_cut_gpu_ms += med.gpu_lod_cut_ms / n;
    row.lod_list_gpu_ms += med.gpu_lod_list_ms / n;
    row.cpu_frame_ms += timed.cpu_frame_ms / n;
    row.frame_ms += timed.frame_ms / n;
    row.frame_gpu_ms += timed.frame_gpu_ms / n;
    row.frame_job_gpu_ms += timed.frame_job_gpu_ms / n;
    for (auto [sum, part] : {std::pair{&row.stage_host, &timed.stage_host},
                             std::pair{&row.frame_host, &timed.frame_host}}) {
        sum->host_record_ms += part->host_record_ms / n;
        sum->host_submit_ms += part->host_submit_ms / n;
        sum->host_wait_ms += part->host_wait_ms / n;
        sum->host_readback_ms += part->host_readback_ms / n;
    }
    // Dispatch counts: the largest of the views' recordings (the view does not change them).
    row.frame_host.dispatches = std::max(row.frame_host.dispatches, timed.frame_host.dispatches);
    row.frame_host.dependent_dispatches =
        std::max(row.frame_host.dependent_dispatches, timed.frame_host.dependent_dispatches);
    row.visible += full.num_visible / static_cast<int64_t>(num_views);
    row.entries += full.num_tile_entries / static_cast<int64_t>(num_views);
    row.error_flags |= full.error_flags;
}

// Worst-view error columns: folds one view's colour error against `reference` into `row`.
void AddViewError(Row& row, const t::geometry::Image& image, const t::geometry::Image& reference) {
    const auto m = t::geometry::ComputeImageErrorMetrics(image, reference, 1.0, 1.0 / 255.0);
    row.psnr = row.has_error ? std::min(row.psnr, m.psnr_db) : m.psnr_db;
    row.has_error = true;
    row.max_abs = std::max(row.max_abs, m.max_abs_error);
    row.over_1_255 = std::max(row.over_1_255, m.fraction_over_threshold);
    row.p999 = std::max(row.p999, t::geometry::ComputeAbsErrorPercentile(image, reference, 0.999));
}

}  // namespace bench
}  // namespace open3d
