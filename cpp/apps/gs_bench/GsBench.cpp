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
#include "GsBenchRows.h"
#include "LodBudgets.h"
#include "StreamBench.h"
#include "Throughput.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/core/CrashReport.h"
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
using namespace open3d::bench;

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
        const bool lod = !budgets.empty() || opt.lod_target_ms > 0.0;
        if (lod || !opt.stream.empty()) {
            // The level-of-detail rows upload every node: refused before the build, which
            // takes minutes at 1e8 splats, when even the leaves cannot fit.
            if (vulkan != nullptr && lod) {
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
            if (lod) {
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
    open3d::core::InstallCrashReport();
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
    app.add_option("--lod-target-ms", opt.lod_target_ms,
                   "Vulkan: also render a path through the views (--lod-target-frames frames "
                   "from each to the next, after 30 at the first) with "
                   "RenderConfig::lod_target_ms, the cut's budget chosen each frame from the "
                   "last frames' GPU times, and print how the frames' GPU times meet the "
                   "target (docs/lod.md)")
        ->check(CLI::PositiveNumber);
    app.add_option("--lod-target-frames", opt.lod_target_frames,
                   "--lod-target-ms: frames from each view to the next")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
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
