// gs-bench: time against error. For each scene, resolution and accuracy/speed knob it
// renders the cameras.json views (or the grid scene) with a backend, reports GPU time per
// stage (timestamp queries), wall-clock time per frame (the stage path, one submission, frames
// in flight with and without readback, batches), memory per splat and the error against the
// CPU reference rendered in the same run. Runs headless (no window, no Filament).
#include <CLI/CLI.hpp>
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

#include "../InputPathValidators.h"
#include "../RunReportingErrors.h"
#include "BenchScenes.h"
#include "LodBudgets.h"
#include "StreamBench.h"
#include "Throughput.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/core/Timer.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/OutputFiles.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamSession.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace {

using namespace open3d;
namespace rendering = visualization::rendering;

struct Options {
    std::vector<std::string> inputs;
    std::vector<std::string> cameras;
    std::string views = "0";
    std::vector<std::string> resolutions;
    std::string backend = "vulkan";
    int grid = 0;
    int64_t first = 0;  // --first: only the first splats of each input
    std::string json;
    int repeat = 10;
    std::string knobs = "all";
    int64_t reference_max_splats = 2000000;
    std::string depth = "none";
    int batch = 0;
    int frames_in_flight = 2;
    std::string lod_budgets;              // --lod-budgets, empty: no level-of-detail rows
    std::string lod_cut_search = "auto";  // --lod-cut-search: comma list
    int lod_supersample = 0;              // --lod-supersample, 0: no filtered reference
    uint64_t max_tile_entries = 0;        // --max-tile-entries, 0: RenderConfig's default
    std::string stream;                   // --stream, empty: no streaming run
    std::string gpu_budget = "2G";
    std::string stream_budget;    // empty: what the pool holds
    bool stream_compact = false;  // --stream-compact: the pool at half precision
    int64_t page_capacity = 65536;
    int64_t reads_per_step = 16;
    double warm_up_seconds = -1.0;  // --warm-up, < 0: until the GPU time settles
    int wall_frames = 50;           // --wall-frames
};

struct Knob {
    std::string name;
    void (*apply)(rendering::RenderConfig&);
};

const std::vector<Knob> kKnobs = {
    {"default", [](rendering::RenderConfig&) {}},
    {"tile-bins",
     [](rendering::RenderConfig& c) { c.sort_mode = rendering::SortMode::kExactTileBins; }},
    {"packed-key",
     [](rendering::RenderConfig& c) { c.sort_mode = rendering::SortMode::kPackedKey32; }},
    {"compact", [](rendering::RenderConfig& c) { c.compact_storage = true; }},
    {"sh<=1", [](rendering::RenderConfig& c) { c.sh_degree = 1; }},
    {"antialias", [](rendering::RenderConfig& c) { c.antialias = true; }},
    {"camera-relative",
     [](rendering::RenderConfig& c) { c.depth_order = rendering::DepthOrder::kCameraRelative; }},
};

struct Row {
    std::string scene, resolution, knob;
    int64_t splats = 0, visible = 0, entries = 0;
    double project_ms = 0, sort_ms = 0, composite_ms = 0, gpu_total_ms = 0, cpu_frame_ms = 0;
    double depth_sort_ms = 0, scan_emit_ms = 0, tile_sort_ms = 0;  // parts of sort_ms
    double bytes_per_splat = 0;
    // Wall clock (Vulkan): one submission per frame waited for, frames in flight without and
    // with readback (ms per frame), and the host's part of a stage-path / one-submission frame.
    double frame_ms = 0, pipelined_ms = 0, pipelined_readback_ms = 0;
    double frame_gpu_ms = 0, frame_job_gpu_ms = 0;
    rendering::RenderStats stage_host, frame_host;  // host_* fields and dispatch counts only
    // --batch: views per second (colour read back as float32 / uint8, or left on the GPU).
    double batch_float_vps = 0, batch_uint8_vps = 0, batch_gpu_only_vps = 0;
    double batch_float_into_buffer_vps = 0;  // float32 into one reused buffer
    // Into rendering::BatchHostMemory (the device copies into it, no host copy).
    double batch_float_host_memory_vps = 0, batch_uint8_host_memory_vps = 0;
    double batch_gpu_ms_per_view = 0;
    int batch_submissions = 0;
    // One device-to-host copy of the float32 batch's bytes alone: the readback's ceiling.
    double batch_copy_gb_per_s = 0, batch_copy_ceiling_vps = 0;
    bool has_error = false;
    double psnr = 0, max_abs = 0, over_1_255 = 0, p999 = 0;
    uint32_t error_flags = 0;
    // Level-of-detail rows (--lod-budgets): the budget, the cut's nodes (mean over views) and
    // the CPU time of the cut and its extraction; their error columns compare with the exact
    // render of the whole scene, not the CPU reference.
    int64_t lod_budget = 0;
    double lod_nodes = 0, lod_cut_ms = 0, hierarchy_build_ms = 0;
    double lod_cut_gpu_ms = 0;   // part of project_ms: the cut's passes on the GPU
    double lod_list_gpu_ms = 0;  // part of lod_cut_gpu_ms: the bits made a list
    bool lod_on_gpu = false;     // the cut chosen by the Vulkan backend, not on the CPU
    // The walk from the root (after the timed frames, view 0's): inner nodes sized, walks.
    int64_t lod_walk_visited = 0;
    int lod_walks = 0;
    // --lod-supersample S: PSNR (worst view) of the cut and of the exact render against the
    // exact render at S x S times the pixels, box-filtered to the row's size.
    int lod_supersample = 0;
    double lod_filtered_psnr = 0, exact_filtered_psnr = 0;
};

// --lod-cut-search's names.
const std::vector<std::pair<std::string, rendering::LodCutSearch>> kLodCutSearches = {
    {"auto", rendering::LodCutSearch::kAuto},
    {"every-node", rendering::LodCutSearch::kEveryNode},
    {"from-root", rendering::LodCutSearch::kFromRoot},
};

std::vector<std::pair<std::string, rendering::LodCutSearch>> ParseLodCutSearches(
    const std::string& text) {
    std::vector<std::pair<std::string, rendering::LodCutSearch>> out;
    std::stringstream items(text);
    for (std::string item; std::getline(items, item, ',');) {
        const auto found = std::find_if(kLodCutSearches.begin(), kLodCutSearches.end(),
                                        [&](const auto& s) { return s.first == item; });
        if (found == kLodCutSearches.end()) {
            core::ThrowError("--lod-cut-search: '{}' is none of auto, every-node, from-root", item);
        }
        out.push_back(*found);
    }
    if (out.empty()) core::ThrowError("--lod-cut-search: give at least one search");
    return out;
}

std::pair<int, int> ParseResolution(const std::string& text) {
    int w = 0, h = 0, used = 0;
    char x = 0;
    // %n: the whole text must be the size ("64x64junk" is refused, not read as 64x64).
    if (std::sscanf(text.c_str(), "%d%c%d%n", &w, &x, &h, &used) != 3 ||
        used != static_cast<int>(text.size()) || (x != 'x' && x != 'X') || w < 1 || h < 1 ||
        w > 16384 || h > 16384) {
        core::ThrowError("--resolution '{}' must look like 1920x1080 (1..16384)", text);
    }
    return {w, h};
}

std::vector<int> ParseViews(const std::string& text, int available) {
    std::vector<int> views;
    if (text == "all") {
        for (int i = 0; i < available; ++i) views.push_back(i);
        return views;
    }
    size_t start = 0;
    while (start <= text.size()) {
        const size_t comma = text.find(',', start);
        const std::string item = text.substr(start, comma - start);
        char* end = nullptr;
        const long v = std::strtol(item.c_str(), &end, 10);
        if (item.empty() || *end != '\0' || v < 0 || v >= available) {
            core::ThrowError("--views: '{}' is not a view index in 0..{}", item, available - 1);
        }
        views.push_back(static_cast<int>(v));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return views;
}

struct SceneJob {
    std::string name;
    t::geometry::PointCloud cloud;
    // One camera per view at the given resolution.
    std::function<std::vector<camera::PinholeCamera>(int w, int h)> cameras;
    std::pair<int, int> native{800, 800};
};

double Median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

// Medians over the timed frames of RunTimedFrames.
struct TimedFrames {
    rendering::RenderStats gpu;     // every gpu_*_ms field is the median of that pass
    double cpu_frame_ms = 0.0;      // stage path: wall time per frame, first submit to last fence
    double frame_ms = 0.0;          // submission path: one submission, waited for
    double frame_gpu_ms = 0.0;      // its passes' GPU time (as gpu, timed in that path)
    double frame_job_gpu_ms = 0.0;  // its submission's GPU time, first to last command
    rendering::RenderStats stage_host, frame_host;  // medians of the host_* fields
};

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

void PrintTable(const std::vector<Row>& rows) {
    std::string last;
    for (const Row& r : rows) {
        const std::string head = r.scene + " @ " + r.resolution;
        if (head != last) {
            std::printf("\n%s: %lld splats\n", head.c_str(), static_cast<long long>(r.splats));
            std::printf("%-11s %9s %10s %8s %8s %8s %9s %9s %7s %8s %9s %9s\n", "knob", "visible",
                        "entries", "proj ms", "sort ms", "comp ms", "GPU ms", "stage ms", "B/splat",
                        "PSNR dB", "max err", ">1/255 %");
            last = head;
        }
        char err[64] = "        -         -         -";
        if (r.has_error) {
            std::snprintf(err, sizeof(err), "%8.1f %9.2e %9.4f", r.psnr, r.max_abs,
                          100.0 * r.over_1_255);
        }
        std::printf(
            "%-11s %9lld %10lld %8.3f %8.3f %8.3f %9.3f %9.2f %7.1f %s  [sort: %.3f depth, "
            "%.3f scan+emit, %.3f tiles]%s\n",
            r.knob.c_str(), static_cast<long long>(r.visible), static_cast<long long>(r.entries),
            r.project_ms, r.sort_ms, r.composite_ms, r.gpu_total_ms, r.cpu_frame_ms,
            r.bytes_per_splat, err, r.depth_sort_ms, r.scan_emit_ms, r.tile_sort_ms,
            r.error_flags ? "  (entries dropped!)" : "");
        if (r.lod_budget > 0 && r.lod_on_gpu) {
            std::printf(
                "%-11s level of detail: cut of %.0f nodes (budget %lld) chosen on the GPU in "
                "%.3f ms (part of project; its list from the bits %.3f ms); error against the "
                "exact render of all %lld splats\n",
                "", r.lod_nodes, static_cast<long long>(r.lod_budget), r.lod_cut_gpu_ms,
                r.lod_list_gpu_ms, static_cast<long long>(r.splats));
            if (r.lod_walks > 0) {
                std::printf("%-11s the walk from the root sized %lld inner nodes in %d walk%s\n",
                            "", static_cast<long long>(r.lod_walk_visited), r.lod_walks,
                            r.lod_walks == 1 ? "" : "s");
            }
        } else if (r.lod_budget > 0) {
            std::printf(
                "%-11s level of detail: cut of %.0f nodes (budget %lld) in %.1f ms on the CPU; "
                "error against the exact render of all %lld splats\n",
                "", r.lod_nodes, static_cast<long long>(r.lod_budget), r.lod_cut_ms,
                static_cast<long long>(r.splats));
        }
        if (r.lod_supersample > 0) {
            std::printf(
                "%-11s against the exact render at %dx%d supersampling, box-filtered: PSNR "
                "%.2f dB (the exact render itself: %.2f dB)\n",
                "", r.lod_supersample, r.lod_supersample, r.lod_filtered_psnr,
                r.exact_filtered_psnr);
        }
        if (r.pipelined_ms > 0) {
            std::printf(
                "%-11s wall ms/frame: one submission %.3f (GPU: passes %.3f, submission %.3f), "
                "in flight %.3f, in flight + readback %.3f; %d dispatches, %d dependent  [host "
                "ms, stage path / one submission: record %.3f / %.3f, submit %.3f / %.3f, wait "
                "%.3f / %.3f]\n",
                "", r.frame_ms, r.frame_gpu_ms, r.frame_job_gpu_ms, r.pipelined_ms,
                r.pipelined_readback_ms, r.frame_host.dispatches, r.frame_host.dependent_dispatches,
                r.stage_host.host_record_ms, r.frame_host.host_record_ms,
                r.stage_host.host_submit_ms, r.frame_host.host_submit_ms, r.stage_host.host_wait_ms,
                r.frame_host.host_wait_ms);
        }
        if (r.batch_float_vps > 0) {
            std::printf(
                "%-11s batch: %.0f views/s float32 readback (%.0f into one reused buffer, %.0f "
                "into BatchHostMemory), %.0f uint8 readback (%.0f into BatchHostMemory), %.0f on "
                "the GPU only; GPU %.3f ms/view, %d submission(s) per batch; the batch's float32 "
                "bytes copied alone to host memory: %.1f GB/s (%.0f views/s)\n",
                "", r.batch_float_vps, r.batch_float_into_buffer_vps, r.batch_float_host_memory_vps,
                r.batch_uint8_vps, r.batch_uint8_host_memory_vps, r.batch_gpu_only_vps,
                r.batch_gpu_ms_per_view, r.batch_submissions, r.batch_copy_gb_per_s,
                r.batch_copy_ceiling_vps);
        }
    }
}

// Writes the rows as JSON through a temporary renamed when complete, so a failed write
// (a full disk) fails the run and leaves no truncated file.
void WriteJson(const std::string& path, const nlohmann::json& rows) {
    t::io::OutputFileSet files;
    files.Write(path, [&](const std::string& temporary) {
        std::ofstream out(temporary);
        out << rows.dump(2) << "\n";
        out.close();
        if (!out) core::ThrowError("--json '{}': writing failed", path);
    });
    files.Commit();
}

// Level-of-detail rows (--lod-budgets), timed with the knobs before any CPU reference: per
// budget, every view's cut rendered and its colour compared with the exact render of the
// whole scene. With Vulkan the scene is the hierarchy's nodes and the cut is chosen on the
// GPU each frame (RenderConfig::lod_budget: its passes are in the projection's time); other
// backends render the CPU cut (CutSplatHierarchy) set as their scene.
void AddLodRows(const Options& opt, const std::vector<int64_t>& budgets, const SceneJob& job,
                const t::geometry::SplatHierarchy& hierarchy, double hierarchy_ms,
                rendering::GaussianSplatBackend& backend,
                const std::vector<camera::PinholeCamera>& cams, const std::string& resolution,
                std::vector<Row>& rows) {
    // The default knob: exact order, float32 storage.
    rendering::RenderConfig config = TimedConfig(opt);
    std::vector<t::geometry::Image> exact, filtered;
    // --lod-supersample: the exact render against the filtered one, worst view (every row's).
    double exact_filtered_psnr = std::numeric_limits<double>::infinity();
    for (const auto& cam : cams) {
        exact.push_back(backend.Render(cam, config).color);
        if (opt.lod_supersample > 0) {
            filtered.push_back(bench::FilteredReference(backend, cam, opt.lod_supersample, config));
            exact_filtered_psnr = std::min(
                exact_filtered_psnr, t::geometry::ComputePSNR(exact.back(), filtered.back(), 1.0));
        }
    }
    // The hierarchy's backend is another device context: the exact scene's buffers go first
    // (the 98M-splat grid held both and failed on an 80 GB card), and come back after it is
    // gone (declared first, so destroyed last).
    struct RestoreScene {
        rendering::GaussianSplatBackend& backend;
        const t::geometry::PointCloud& cloud;
        bool released = false;
        ~RestoreScene() {
            if (released) backend.SetScene(cloud);
        }
    } restore{backend, job.cloud};
    auto lod_backend = rendering::CreateGaussianSplatBackend(opt.backend);
    auto* vulkan = dynamic_cast<rendering::vulkan::GaussianSplatVulkanBackend*>(lod_backend.get());
    if (vulkan != nullptr) {
        backend.ReleaseResources();
        restore.released = true;
        vulkan->SetFramesInFlight(opt.frames_in_flight);
        vulkan->CheckHierarchyFits(job.cloud.NumPoints(),
                                   job.cloud.GetGaussianSplatArrays().sh_degree);
        vulkan->SetSceneHierarchy(job.cloud, hierarchy);
    }
    const double n = static_cast<double>(cams.size());
    const auto searches = ParseLodCutSearches(opt.lod_cut_search);
    // A row per budget and search, budgets first.
    struct LodRow {
        int64_t budget;
        std::string search_name;
        rendering::LodCutSearch search;
    };
    std::vector<LodRow> lod_rows;
    for (const int64_t budget : budgets) {
        for (const auto& [name, search] : searches) lod_rows.push_back({budget, name, search});
    }
    for (const auto& [budget, search_name, search] : lod_rows) {
        Row row;
        row.scene = job.name;
        row.resolution = resolution;
        row.knob = "lod " + bench::BudgetLabel(budget);
        if (searches.size() > 1) row.knob += " " + search_name;
        config.lod_cut_search = search;
        row.splats = job.cloud.NumPoints();
        row.lod_budget = budget;
        row.lod_on_gpu = vulkan != nullptr;
        row.hierarchy_build_ms = hierarchy_ms;
        if (opt.lod_supersample > 0) {
            row.lod_supersample = opt.lod_supersample;
            row.exact_filtered_psnr = exact_filtered_psnr;
            row.lod_filtered_psnr = std::numeric_limits<double>::infinity();
        }
        config.lod_budget = static_cast<uint64_t>(budget);
        for (size_t v = 0; v < cams.size(); ++v) {
            double scene_nodes = static_cast<double>(hierarchy.NumNodes());
            if (vulkan == nullptr) {
                const bench::LodCut cut = bench::CutForView(hierarchy, job.cloud, cams[v], budget);
                row.lod_nodes += static_cast<double>(cut.nodes) / n;
                row.lod_cut_ms += cut.cut_ms / n;
                lod_backend->SetScene(cut.cloud);
                scene_nodes = static_cast<double>(cut.nodes);
            }
            const rendering::RenderOutput out = lod_backend->Render(cams[v], config);
            if (vulkan != nullptr)
                row.lod_nodes += static_cast<double>(out.stats.lod_cut_nodes) / n;
            const TimedFrames timed = RunTimedFrames(*lod_backend, cams[v], config, opt.repeat,
                                                     opt.depth, opt.warm_up_seconds);
            AddView(row, timed, out.stats, cams.size());
            row.bytes_per_splat += static_cast<double>(out.stats.gpu_scene_bytes) / scene_nodes / n;
            if (vulkan != nullptr) {
                const auto [in_flight, with_readback] =
                    PipelinedMs(opt, *vulkan, {cams[v]}, config);
                row.pipelined_ms += in_flight / n;
                row.pipelined_readback_ms += with_readback / n;
            }
            AddViewError(row, out.color, exact[v]);
            if (opt.lod_supersample > 0) {
                row.lod_filtered_psnr = std::min(
                    row.lod_filtered_psnr, t::geometry::ComputePSNR(out.color, filtered[v], 1.0));
            }
            if (vulkan != nullptr && v == 0) {
                const rendering::RenderStats after = lod_backend->Render(cams[v], config).stats;
                row.lod_walk_visited = after.lod_walk_visited;
                row.lod_walks = after.lod_walks;
            }
        }
        row.gpu_total_ms = row.project_ms + row.sort_ms + row.composite_ms;
        rows.push_back(row);
    }
}

int Run(const Options& opt) {
    // The JSON output is checked before minutes of benchmarking, not after them.
    if (!opt.json.empty()) {
        if (t::io::LowerCaseExtension(opt.json) != "json") {
            core::ThrowError("--json '{}': the file name must end in .json", opt.json);
        }
        t::io::CheckOutputPath("--json", opt.json);
    }
    std::vector<std::pair<int, int>> resolutions;  // refused before any scene loads
    for (const auto& r : opt.resolutions) resolutions.push_back(ParseResolution(r));
    uint64_t stream_gpu_budget = 0;
    if (!opt.stream.empty()) {
        t::io::CheckOutputPath("--stream", opt.stream);
        stream_gpu_budget = visualization::rendering::ParseByteSize(opt.gpu_budget, "--gpu-budget");
    }
    std::vector<t::io::NamedInput> inputs;
    for (const std::string& path : opt.inputs) inputs.push_back({"--input", path});
    for (const std::string& path : opt.cameras) inputs.push_back({"--cameras", path});
    t::io::CheckOutputIsNotAnInput("--json", opt.json, inputs);
    t::io::CheckOutputIsNotAnInput("--stream", opt.stream, inputs);
    if (!opt.json.empty() && !opt.stream.empty() && t::io::SameOutputPath(opt.json, opt.stream)) {
        core::ThrowError("--json and --stream are the same file '{}'; give each its own path",
                         opt.json);
    }
    if (opt.batch > 0 && opt.backend != "vulkan") {
        core::ThrowError("--batch measures the Vulkan backend's batches: use --backend vulkan");
    }
    const std::vector<int64_t> budgets =
        opt.lod_budgets.empty() ? std::vector<int64_t>{} : bench::ParseBudgets(opt.lod_budgets);
    ParseLodCutSearches(opt.lod_cut_search);  // refused before the scenes load
    if (opt.lod_supersample > 0 && budgets.empty()) {
        core::ThrowError("--lod-supersample compares the --lod-budgets rows: give --lod-budgets");
    }
    rendering::vulkan::RegisterVulkanBackend();
    std::vector<SceneJob> jobs;
    if (opt.inputs.empty()) core::ThrowError("--input is required (a .ply or .splat scene)");
    if (opt.grid > 0 && opt.first > 0) {
        core::ThrowError(
            "--first takes the first splats of each --input; --grid tiles a whole one");
    }
    if (opt.grid > 0) {
        if (opt.cameras.empty())
            core::ThrowError("--grid needs --cameras (view 0 sets the rotation)");
        t::geometry::PointCloud tile;
        t::io::ReadPointCloud(opt.inputs[0], tile);
        t::io::RequireGaussianSplat(opt.inputs[0], tile);
        const auto view = camera::ReadCamerasJson(opt.cameras[0]).at(0).camera;
        double spacing = 0;
        SceneJob job;
        job.cloud = bench::MakeGridScene(tile, opt.grid, &spacing);
        job.name = fmt::format("grid{}x{}", opt.grid, opt.grid);
        job.native = {1920, 1080};
        job.cameras = [tile, view, k = opt.grid, spacing](int w, int h) {
            return std::vector<camera::PinholeCamera>{
                bench::MakeGridCamera(tile, view, k, spacing, w, h)};
        };
        jobs.push_back(std::move(job));
    } else {
        if (opt.cameras.size() != opt.inputs.size()) {
            core::ThrowError("give one --cameras per --input ({} inputs, {} cameras)",
                             opt.inputs.size(), opt.cameras.size());
        }
        for (size_t i = 0; i < opt.inputs.size(); ++i) {
            SceneJob job;
            t::io::ReadPointCloud(opt.inputs[i], job.cloud);
            t::io::RequireGaussianSplat(opt.inputs[i], job.cloud);
            job.name = std::filesystem::path(opt.inputs[i]).filename().string();
            if (opt.first > 0) {
                job.cloud = bench::FirstSplats(job.cloud, opt.first);
                job.name += fmt::format("[first {}]", opt.first);
            }
            std::vector<camera::PinholeCamera> views;
            for (const auto& v : camera::ReadCamerasJson(opt.cameras[i])) views.push_back(v.camera);
            const std::vector<int> chosen = ParseViews(opt.views, static_cast<int>(views.size()));
            job.native = {views.at(0).width, views.at(0).height};
            job.cameras = [views, chosen](int w, int h) {
                std::vector<camera::PinholeCamera> out;
                for (int v : chosen) out.push_back(bench::ScaleViewTo(views[v], w, h));
                return out;
            };
            jobs.push_back(std::move(job));
        }
    }

    std::vector<Knob> knobs;
    for (const Knob& k : kKnobs) {
        if (opt.knobs == "all" || opt.knobs.find(k.name) != std::string::npos) knobs.push_back(k);
    }
    if (knobs.empty()) core::ThrowError("--knobs '{}' selects none of the known knobs", opt.knobs);

    std::vector<Row> rows;
    // --stream's runs: a JSON row each (knob "stream").
    struct StreamRow {
        std::string scene, resolution;
        int64_t splats;
        std::string gpu_budget;
        bench::StreamBenchResult result;
    };
    std::vector<StreamRow> streams;
    std::string device_name = opt.backend;
    for (SceneJob& job : jobs) {
        auto backend = rendering::CreateGaussianSplatBackend(opt.backend);
        auto* vulkan = dynamic_cast<rendering::vulkan::GaussianSplatVulkanBackend*>(backend.get());
        if (vulkan != nullptr) {
            vulkan->SetFramesInFlight(opt.frames_in_flight);
            device_name = vulkan->GetContext().GetDeviceInfo().name;
        }
        backend->SetScene(job.cloud);
        const bool reference =
            opt.reference_max_splats > 0 && job.cloud.NumPoints() <= opt.reference_max_splats;
        t::geometry::SplatHierarchy hierarchy;
        double hierarchy_ms = 0.0;
        if (!budgets.empty() || !opt.stream.empty()) {
            // The level-of-detail rows upload every node: refused before the build, which
            // takes minutes at 1e8 splats, when even the leaves cannot fit.
            if (vulkan != nullptr && !budgets.empty()) {
                vulkan->CheckHierarchyFits(job.cloud.NumPoints(),
                                           job.cloud.GetGaussianSplatArrays().sh_degree);
            }
            const auto start = std::chrono::steady_clock::now();
            hierarchy = t::geometry::BuildSplatHierarchy(job.cloud);
            hierarchy_ms = core::MillisecondsSince(start);
            std::printf(
                "%s: level-of-detail hierarchy of %lld splats and %lld inner nodes built "
                "in %.0f ms\n",
                job.name.c_str(), static_cast<long long>(hierarchy.num_leaves),
                static_cast<long long>(hierarchy.NumInner()), hierarchy_ms);
        }
        auto job_resolutions = resolutions;
        if (job_resolutions.empty()) job_resolutions.push_back(job.native);
        if (!opt.stream.empty()) {
            // The first resolution's first view, against the exact render of the whole scene.
            const camera::PinholeCamera cam =
                job.cameras(job_resolutions[0].first, job_resolutions[0].second).at(0);
            const rendering::RenderConfig config = TimedConfig(opt);
            bench::StreamBenchOptions stream;
            stream.path = opt.stream;
            stream.gpu_budget = stream_gpu_budget;
            stream.splat_budget =
                opt.stream_budget.empty() ? 0 : bench::ParseBudgets(opt.stream_budget).at(0);
            stream.page_capacity = opt.page_capacity;
            stream.reads_per_step = opt.reads_per_step;
            stream.compact_storage = opt.stream_compact;
            const bench::StreamBenchResult result = bench::RunStreamBench(
                job.cloud, hierarchy, cam, config, backend->Render(cam, config).color, stream);
            streams.push_back(
                {job.name,
                 fmt::format("{}x{}", job_resolutions[0].first, job_resolutions[0].second),
                 job.cloud.NumPoints(), opt.gpu_budget, result});
        }
        for (const auto& [w, h] : job_resolutions) {
            const auto cams = job.cameras(w, h);
            // Phase 1, the GPU alone: every knob and view is timed before any CPU reference
            // runs, because seconds of CPU work let the GPU's clocks fall and a short
            // warm-up did not always bring them back (H100: up to 2.6x slower rows).
            const size_t first_row = rows.size();
            std::vector<std::vector<t::geometry::Image>> images(knobs.size());
            for (size_t k = 0; k < knobs.size(); ++k) {
                rendering::RenderConfig config = TimedConfig(opt);
                knobs[k].apply(config);
                Row row;
                row.scene = job.name;
                row.resolution = fmt::format("{}x{}", w, h);
                row.knob = knobs[k].name;
                row.splats = job.cloud.NumPoints();
                for (size_t v = 0; v < cams.size(); ++v) {
                    // One full frame for the error columns, then timed frames without
                    // readback (per-pass medians).
                    rendering::RenderOutput out = backend->Render(cams[v], config);
                    const TimedFrames timed = RunTimedFrames(*backend, cams[v], config, opt.repeat,
                                                             opt.depth, opt.warm_up_seconds);
                    AddView(row, timed, out.stats, cams.size());
                    row.bytes_per_splat =
                        static_cast<double>(out.stats.gpu_scene_bytes) / row.splats;
                    if (reference) images[k].push_back(std::move(out.color));
                }
                row.gpu_total_ms = row.project_ms + row.sort_ms + row.composite_ms;
                if (vulkan != nullptr) {
                    std::tie(row.pipelined_ms, row.pipelined_readback_ms) =
                        PipelinedMs(opt, *vulkan, cams, config);
                    if (opt.batch > 0) {
                        const int repeats = 5;
                        const double batch_warm_up =
                            opt.warm_up_seconds < 0.0 ? 1.0 : opt.warm_up_seconds;
                        rendering::BatchOptions o;
                        const bench::BatchThroughput f = bench::MeasureBatch(
                            *vulkan, cams, config, o, opt.batch, repeats, batch_warm_up);
                        // Into the caller's memory, allocated and faulted in once (what
                        // Python's render_batch(out=...) does).
                        std::vector<uint8_t> buffer(size_t(opt.batch) * cams[0].width *
                                                    cams[0].height * 16);
                        o.color_destination = buffer.data();
                        const bench::BatchThroughput b = bench::MeasureBatch(
                            *vulkan, cams, config, o, opt.batch, repeats, batch_warm_up);
                        o.color_destination = nullptr;
                        row.batch_float_into_buffer_vps = b.views_per_second;
                        // Into memory the device copies into directly (imported where the
                        // device can: no host copy at all).
                        o.color_memory = rendering::BatchHostMemory(buffer.size());
                        row.batch_float_host_memory_vps =
                            bench::MeasureBatch(*vulkan, cams, config, o, opt.batch, repeats,
                                                batch_warm_up)
                                .views_per_second;
                        o.color_uint8 = true;
                        row.batch_uint8_host_memory_vps =
                            bench::MeasureBatch(*vulkan, cams, config, o, opt.batch, repeats,
                                                batch_warm_up)
                                .views_per_second;
                        o.color_memory = rendering::BatchHostMemory();
                        const bench::BatchThroughput u = bench::MeasureBatch(
                            *vulkan, cams, config, o, opt.batch, repeats, batch_warm_up);
                        o.read_back = false;
                        const bench::BatchThroughput g = bench::MeasureBatch(
                            *vulkan, cams, config, o, opt.batch, repeats, batch_warm_up);
                        row.batch_float_vps = f.views_per_second;
                        row.batch_uint8_vps = u.views_per_second;
                        row.batch_gpu_only_vps = g.views_per_second;
                        row.batch_gpu_ms_per_view = f.gpu_ms_per_view;
                        row.batch_submissions = f.submissions_per_batch;
                        row.batch_copy_gb_per_s = bench::MeasureDeviceToHostGBs(
                            vulkan->GetContext(), buffer.size(), repeats);
                        row.batch_copy_ceiling_vps =
                            row.batch_copy_gb_per_s * 1e9 * opt.batch / double(buffer.size());
                    }
                }
                rows.push_back(row);
            }
            if (!budgets.empty()) {
                AddLodRows(opt, budgets, job, hierarchy, hierarchy_ms, *backend, cams,
                           fmt::format("{}x{}", w, h), rows);
            }
            if (!reference) continue;
            // Phase 2: the error columns against CPU references, keyed by what changes the
            // reference image (SH cap, antialias).
            std::map<std::pair<int, bool>, std::vector<t::geometry::Image>> refs;
            for (size_t k = 0; k < knobs.size(); ++k) {
                rendering::RenderConfig config;
                knobs[k].apply(config);
                Row& row = rows[first_row + k];
                for (size_t v = 0; v < cams.size(); ++v) {
                    auto& ref = refs[{config.sh_degree, config.antialias}];
                    if (ref.size() <= v) {
                        // The timed rows' entry cap: with the default 2^26 the reference
                        // dropped the far splats of the 98M grid's 116M entries (15.6 dB).
                        rendering::RenderConfig ref_config = TimedConfig(opt);
                        ref_config.sh_degree = config.sh_degree;
                        ref_config.antialias = config.antialias;
                        ref.push_back(
                            rendering::cpu::RenderReference(job.cloud, cams[v], ref_config).color);
                    }
                    AddViewError(row, images[k][v], ref[v]);
                }
            }
        }
    }
    const std::string clock = bench::ReadGpuClockMHz();
    std::printf("device: %s%s\n", device_name.c_str(),
                clock.empty() ? "" : (", SM clock " + clock + " MHz (current/max)").c_str());
    PrintTable(rows);
    if (!opt.json.empty()) {
        nlohmann::json out = nlohmann::json::array();
        for (const Row& r : rows) {
            out.push_back({{"scene", r.scene},
                           {"resolution", r.resolution},
                           {"knob", r.knob},
                           {"splats", r.splats},
                           {"visible", r.visible},
                           {"tile_entries", r.entries},
                           {"gpu_project_ms", r.project_ms},
                           {"gpu_sort_ms", r.sort_ms},
                           {"gpu_depth_sort_ms", r.depth_sort_ms},
                           {"gpu_scan_emit_ms", r.scan_emit_ms},
                           {"gpu_tile_sort_ms", r.tile_sort_ms},
                           {"gpu_composite_ms", r.composite_ms},
                           {"gpu_total_ms", r.gpu_total_ms},
                           {"cpu_frame_ms", r.cpu_frame_ms},
                           {"frame_ms", r.frame_ms},
                           {"frame_gpu_passes_ms", r.frame_gpu_ms},
                           {"frame_gpu_submission_ms", r.frame_job_gpu_ms},
                           {"frame_dispatches", r.frame_host.dispatches},
                           {"frame_dependent_dispatches", r.frame_host.dependent_dispatches},
                           {"pipelined_frame_ms", r.pipelined_ms},
                           {"pipelined_readback_frame_ms", r.pipelined_readback_ms},
                           {"pipelined_fps", r.pipelined_ms > 0 ? 1000.0 / r.pipelined_ms : 0.0},
                           {"pipelined_readback_fps",
                            r.pipelined_readback_ms > 0 ? 1000.0 / r.pipelined_readback_ms : 0.0},
                           {"host_stage_ms",
                            {{"record", r.stage_host.host_record_ms},
                             {"submit", r.stage_host.host_submit_ms},
                             {"wait", r.stage_host.host_wait_ms},
                             {"readback", r.stage_host.host_readback_ms}}},
                           {"host_frame_ms",
                            {{"record", r.frame_host.host_record_ms},
                             {"submit", r.frame_host.host_submit_ms},
                             {"wait", r.frame_host.host_wait_ms},
                             {"readback", r.frame_host.host_readback_ms}}},
                           {"device", device_name},
                           {"gpu_clock_mhz", clock},
                           {"gpu_bytes_per_splat", r.bytes_per_splat},
                           {"error_flags", r.error_flags}});
            if (r.batch_float_vps > 0) {
                out.back()["batch"] = {
                    {"views", opt.batch},
                    {"views_per_second_float32", r.batch_float_vps},
                    {"views_per_second_float32_into_buffer", r.batch_float_into_buffer_vps},
                    {"views_per_second_float32_into_host_memory", r.batch_float_host_memory_vps},
                    {"views_per_second_uint8_into_host_memory", r.batch_uint8_host_memory_vps},
                    {"views_per_second_uint8", r.batch_uint8_vps},
                    {"views_per_second_no_readback", r.batch_gpu_only_vps},
                    {"gpu_ms_per_view", r.batch_gpu_ms_per_view},
                    {"submissions", r.batch_submissions},
                    {"device_to_host_copy_gb_per_s", r.batch_copy_gb_per_s},
                    {"float32_copy_ceiling_views_per_second", r.batch_copy_ceiling_vps}};
            }
            if (r.lod_budget > 0) {
                out.back()["lod"] = {{"budget", r.lod_budget},
                                     {"nodes", r.lod_nodes},
                                     {"cut_cpu_ms", r.lod_cut_ms},
                                     {"cut_gpu_ms", r.lod_cut_gpu_ms},
                                     {"list_gpu_ms", r.lod_list_gpu_ms},
                                     {"cut_on_gpu", r.lod_on_gpu},
                                     {"walk_visited", r.lod_walk_visited},
                                     {"walks", r.lod_walks},
                                     {"hierarchy_build_ms", r.hierarchy_build_ms},
                                     {"error_against", "exact render of the whole scene"}};
                if (r.lod_supersample > 0) {
                    out.back()["lod"]["supersample"] = r.lod_supersample;
                    out.back()["lod"]["psnr_db_against_filtered"] = r.lod_filtered_psnr;
                    out.back()["lod"]["exact_psnr_db_against_filtered"] = r.exact_filtered_psnr;
                }
            }
            if (r.has_error) {
                out.back()["psnr_db_worst_view"] = r.psnr;
                out.back()["max_abs_error"] = r.max_abs;
                out.back()["fraction_over_1_255"] = r.over_1_255;
                out.back()["p999_abs_error"] = r.p999;
            }
        }
        for (const StreamRow& s : streams) {
            const bench::StreamBenchResult& r = s.result;
            out.push_back({{"scene", s.scene},
                           {"resolution", s.resolution},
                           {"knob", "stream"},
                           {"splats", s.splats},
                           {"stream",
                            {{"gpu_budget", s.gpu_budget},
                             {"compact_storage", r.compact_storage},
                             {"file_pages", r.file_pages},
                             {"pool_pages", r.pool_pages},
                             {"pool_splats", r.pool_splats},
                             {"bytes_per_splat", r.bytes_per_splat},
                             {"pool_ready_ms", r.pool_ready_ms},
                             {"first_image_ms", r.first_image_ms},
                             {"first_image_psnr_db", r.first_image_psnr_db},
                             {"converged_ms", r.converged_ms},
                             {"steps", r.steps},
                             {"pages_read", r.pages_read},
                             {"bytes_read", r.bytes_read},
                             {"evictions", r.evictions},
                             {"cut_nodes", r.cut_nodes},
                             {"pool_full", r.pool_full},
                             {"error_against", "exact render of the whole scene"}}},
                           {"psnr_db_worst_view", r.psnr_db},
                           {"max_abs_error", r.max_abs_error},
                           {"fraction_over_1_255", r.fraction_over_1_255}});
        }
        WriteJson(opt.json, out);
        std::printf("\nwrote %s\n", opt.json.c_str());
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    Options opt;
    CLI::App app{
        "gs-bench: GPU time per stage against error versus the CPU reference.\n"
        "Real scenes: one --cameras per --input, views from --views at each --resolution\n"
        "(fx = fy = fx_json * H / H_json, principal point at the centre). --grid K builds\n"
        "K x K copies of the first --input with the camera defined in docs/benchmark.md.\n"
        "Knobs: default, tile-bins, packed-key, compact, sh<=1, antialias, camera-relative. The "
        "error\n"
        "columns compare the colour with the CPU reference (default knobs but the SH cap and\n"
        "antialias) rendered in the same run (worst view).",
        "gs-bench"};
    app.add_option("-i,--input", opt.inputs, "Scene file(s) in any format gs-convert reads")
        ->check(open3d::apps::ReadableInput(true))
        ->required();
    app.add_option("--cameras", opt.cameras, "cameras.json per input")
        ->check(open3d::apps::ReadableInput(false));
    app.add_option("--views", opt.views, "View indices, e.g. 0,5,9, or 'all'")
        ->capture_default_str();
    app.add_option("--resolution", opt.resolutions,
                   "WxH, repeatable (default: the camera's own size; 1920x1080 for --grid)");
    app.add_option("--backend", opt.backend, "Backend to time")
        ->check(CLI::IsMember({"vulkan", "cpu"}))
        ->capture_default_str();
    app.add_option("--first", opt.first,
                   "Only the first N splats of each input (1 or 1000: a frame's fixed cost)")
        ->check(CLI::PositiveNumber);
    app.add_option("--grid", opt.grid, "Tiled large scene: K x K copies of the first input")
        ->check(CLI::Range(1, 64));
    app.add_option("--json", opt.json,
                   "Write machine-readable results here (.json; its folder must exist, checked "
                   "before any work; a failed write fails the run)");
    app.add_option("--repeat", opt.repeat,
                   "Timed frames per view and knob (medians, after warm-up frames until the GPU "
                   "time settles)")
        ->check(CLI::Range(1, 10000))
        ->capture_default_str();
    app.add_option("--warm-up", opt.warm_up_seconds,
                   "Seconds of warm-up frames before each timed row (and batch measurement); "
                   "default: until the GPU time stops falling (1-10 s; batches 1 s). 0 times "
                   "at once: for smoke tests, not for numbers")
        ->check(CLI::Range(0.0, 600.0));
    app.add_option("--wall-frames", opt.wall_frames,
                   "Vulkan: frames of each frames-in-flight wall-clock measurement (at least "
                   "--repeat)")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    app.add_option("--knobs", opt.knobs, "Comma list of knobs or 'all'")->capture_default_str();
    app.add_option("--depth", opt.depth,
                   "Depth images the timed frames also compute (none: colour only, as the "
                   "original 3DGS forward pass)")
        ->check(CLI::IsMember({"none", "expected", "median", "both"}))
        ->capture_default_str();
    app.add_option("--batch", opt.batch,
                   "Vulkan: also render batches of N views (the chosen views repeated) and report "
                   "views per second with float32 and uint8 readback and without readback, and "
                   "the GB/s of the batch's float32 bytes copied alone to host memory")
        ->check(CLI::Range(1, 4096));
    app.add_option("--frames-in-flight", opt.frames_in_flight,
                   "Vulkan: frame slots of the submission path (1: no overlap)")
        ->check(CLI::Range(1, 4))
        ->capture_default_str();
    app.add_option(
        "--lod-budgets", opt.lod_budgets,
        "Also render each view's level-of-detail cut under these splat budgets (comma "
        "list, k = 1000, M = 1000000, e.g. 500k,1M,2M): one row per budget, its error "
        "columns against the exact render of the whole scene (the hierarchy is built "
        "once per scene; with Vulkan the cut is chosen on the GPU each frame, else on the "
        "CPU; docs/lod.md)");
    app.add_option("--lod-supersample", opt.lod_supersample,
                   "--lod-budgets rows also compare the cut and the exact render with the "
                   "exact render at S x S times the pixels, box-filtered to the row's size "
                   "(what the view's splats look like with less aliasing; docs/lod.md)")
        ->check(CLI::Range(2, 8));
    app.add_option("--lod-cut-search", opt.lod_cut_search,
                   "Vulkan: how the GPU finds the cut, a comma list for one row each: auto, "
                   "every-node (size every inner node), from-root (walk down from the root "
                   "from the view's previous threshold); the cut is the same")
        ->capture_default_str();
    app.add_option("--max-tile-entries", opt.max_tile_entries,
                   "Tile entries a frame may hold before the farthest splats' are dropped "
                   "(RenderConfig::max_tile_entries_total; default 2^26 = 67,108,864; the "
                   "Vulkan sort takes up to the device's limit: 1,073,741,823 on an H200, "
                   "33,554,432 on lavapipe)")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 40));
    app.add_option("--stream", opt.stream,
                   "Write the scene's hierarchy as a paged file here, then stream it back into "
                   "a GPU pool of --gpu-budget for the first view, rendering after every step: "
                   "prints the time to the first image and to the converged one and the "
                   "converged image's error against the exact render (Vulkan; "
                   "docs/streaming.md)");
    app.add_option("--gpu-budget", opt.gpu_budget,
                   "--stream: bytes of the pool's splat storage (K, M, G = powers of 1024)")
        ->capture_default_str();
    app.add_option("--stream-budget", opt.stream_budget,
                   "--stream: splats per cut (k = 1000, M = 1000000; default: what the pool "
                   "holds)");
    app.add_flag("--stream-compact", opt.stream_compact,
                 "--stream: the pool at half precision (RenderConfig::compact_storage's "
                 "packing, about 1.8 times the splats in --gpu-budget), its frames drawn so; "
                 "the error columns still compare with the exact float32 render");
    app.add_option("--page-capacity", opt.page_capacity, "--stream: nodes per page")
        ->check(CLI::Range(int64_t(8), int64_t(1) << 30))
        ->capture_default_str();
    app.add_option("--reads-per-step", opt.reads_per_step,
                   "--stream: pages read from the file per step (one rendered frame each)")
        ->check(CLI::Range(int64_t(1), int64_t(1) << 20))
        ->capture_default_str();
    app.add_option("--reference-max-splats", opt.reference_max_splats,
                   "Skip the CPU reference for scenes larger than this (0: never compare)")
        ->capture_default_str();
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }
    return open3d::apps::RunReportingErrors("gs-bench", [&opt] { return Run(opt); });
}
