// gs-bench's rows and options, shared by its parts: the timing of frames (BenchTiming.cpp),
// the table and JSON (BenchReport.cpp), the level-of-detail rows (LodRows.cpp) and the run
// itself (GsBench.cpp).
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace open3d {
namespace bench {

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
    double lod_target_ms = 0.0;           // --lod-target-ms, 0: no path with a frame-time target
    int lod_target_frames = 10;           // --lod-target-frames: per view of that path
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

inline const std::vector<Knob> kKnobs = {
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

struct SceneJob {
    std::string name;
    t::geometry::PointCloud cloud;
    // One camera per view at the given resolution.
    std::function<std::vector<camera::PinholeCamera>(int w, int h)> cameras;
    std::pair<int, int> native{800, 800};
};

// Medians over the timed frames of RunTimedFrames.
struct TimedFrames {
    rendering::RenderStats gpu;     // every gpu_*_ms field is the median of that pass
    double cpu_frame_ms = 0.0;      // stage path: wall time per frame, first submit to last fence
    double frame_ms = 0.0;          // submission path: one submission, waited for
    double frame_gpu_ms = 0.0;      // its passes' GPU time (as gpu, timed in that path)
    double frame_job_gpu_ms = 0.0;  // its submission's GPU time, first to last command
    rendering::RenderStats stage_host, frame_host;  // medians of the host_* fields
};

double Median(std::vector<double> v);

// Medians of the host_* fields of `frames`.
rendering::RenderStats MedianHost(const std::vector<rendering::RenderStats>& frames);

// Times `frames` frames (geometry stage + composite stage, no readback) after warm-up frames
// (`warm_up_seconds` of them, or with a negative value until the GPU time settles), and returns the
// median of each GPU pass and of the CPU wall time per frame. Frames follow each other with only
// the submit/fence gap, so a GPU that lowers its clocks when idle (every NVIDIA board does) is
// timed at full clock: with a readback between frames the H100 ran the same depth sort 2.5-5x
// slower. (Run loops time everything before the CPU references: see Run.)
TimedFrames RunTimedFrames(rendering::GaussianSplatBackend& backend,
                           const camera::PinholeCamera& camera,
                           const rendering::RenderConfig& config, int frames,
                           const std::string& depth, double warm_up_seconds);

// The configuration every timed row starts from: geometry re-run per frame, and the entry
// cap of --max-tile-entries where given.
rendering::RenderConfig TimedConfig(const Options& opt);

// Wall ms per frame with frames in flight over `cams`, colour only, without and with the
// RGBA32F readback, each over max(--wall-frames, --repeat) frames.
std::pair<double, double> PipelinedMs(const Options& opt,
                                      rendering::vulkan::GaussianSplatVulkanBackend& vulkan,
                                      const std::vector<camera::PinholeCamera>& cams,
                                      const rendering::RenderConfig& config);

// Adds one view's timed frames and its full frame's counts to `row`, as the mean over
// `num_views` views.
void AddView(Row& row, const TimedFrames& timed, const rendering::RenderStats& full,
             size_t num_views);

// Worst-view error columns: folds one view's colour error against `reference` into `row`.
void AddViewError(Row& row, const t::geometry::Image& image, const t::geometry::Image& reference);

void PrintTable(const std::vector<Row>& rows);

// Writes the rows as JSON through a temporary renamed when complete, so a failed write
// (a full disk) fails the run and leaves no truncated file.
void WriteJson(const std::string& path, const nlohmann::json& rows);

std::vector<std::pair<std::string, rendering::LodCutSearch>> ParseLodCutSearches(
    const std::string& text);

// Level-of-detail rows (--lod-budgets), timed with the knobs before any CPU reference: per
// budget, every view's cut rendered and its colour compared with the exact render of the
// whole scene. With Vulkan the scene is the hierarchy's nodes and the cut is chosen on the
// GPU each frame (RenderConfig::lod_budget: its passes are in the projection's time); other
// backends render the CPU cut (CutSplatHierarchy) set as their scene.
void AddLodRows(const Options& opt, const std::vector<int64_t>& budgets, const SceneJob& job,
                const t::geometry::SplatHierarchy& hierarchy, double hierarchy_ms,
                rendering::GaussianSplatBackend& backend,
                const std::vector<camera::PinholeCamera>& cams, const std::string& resolution,
                std::vector<Row>& rows);

}  // namespace bench
}  // namespace open3d
