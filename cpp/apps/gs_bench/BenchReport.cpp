// gs-bench: the table printed at the end and the JSON file of the rows.
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

}  // namespace bench
}  // namespace open3d
