#include "StreamBench.h"

#include <fmt/format.h>

#include <fcntl.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "open3d/core/Exception.h"
#include "open3d/core/Timer.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/t/io/OutputFiles.h"
#include "open3d/t/io/SplatPageFile.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamSession.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanBackendRegistry.h"

namespace open3d {
namespace bench {

namespace rendering = visualization::rendering;

StreamBenchResult RunStreamBench(const t::geometry::PointCloud& scene,
                                 const t::geometry::SplatHierarchy& hierarchy,
                                 const camera::PinholeCamera& camera,
                                 const rendering::RenderConfig& config,
                                 const t::geometry::Image& exact,
                                 const StreamBenchOptions& options) {
    {
        const auto start = std::chrono::steady_clock::now();
        // Through a temporary renamed when complete: a failed write (a full disk) leaves
        // no partial file where the path was.
        t::io::OutputFileSet files;
        files.Write(options.path, [&](const std::string& path) {
            t::io::WriteSplatPages(path, scene, hierarchy, options.page_capacity);
        });
        files.Commit();
        std::printf("stream: wrote %s (%lld nodes, pages of %lld) in %.0f ms\n",
                    options.path.c_str(), static_cast<long long>(hierarchy.NumNodes()),
                    static_cast<long long>(options.page_capacity), core::MillisecondsSince(start));
    }
    // The backend exists before the load starts, as in a viewer that opens a scene.
    auto made = rendering::CreateGaussianSplatBackend("vulkan");
    auto* backend = dynamic_cast<rendering::vulkan::GaussianSplatVulkanBackend*>(made.get());
    if (backend == nullptr) core::ThrowError("--stream needs the Vulkan backend");

    const auto start = std::chrono::steady_clock::now();
    const t::io::SplatPageFile file(options.path);
    const bool compact = options.compact_storage;
    const double bytes_per_splat = rendering::StreamPoolBytesPerSplat(file.ShDegree(), compact);
    const int64_t pool_pages =
        rendering::StreamPoolPages(file, options.gpu_budget, backend->MaxSceneSplats(), compact);
    const int64_t pool_splats = pool_pages * file.PageCapacity();
    const int64_t budget = options.splat_budget > 0 ? options.splat_budget : pool_splats;
    rendering::SplatStreamer streamer(file, pool_pages, budget);
    backend->SetScenePool(pool_splats, file.ShDegree(), file.CenterMin(), file.CenterMax(),
                          compact);
    rendering::RenderConfig pool_config = config;
    pool_config.compact_storage = compact;
    std::printf(
        "stream: %s, %.2f GB on disk, %lld pages; pool %lld pages = %lld splats = %.2f GB "
        "(%.0f bytes a splat%s), cut budget %lld\n",
        options.path.c_str(), file.FileBytes() / 1e9, static_cast<long long>(file.NumPages()),
        static_cast<long long>(pool_pages), static_cast<long long>(pool_splats),
        pool_splats * bytes_per_splat / 1e9, bytes_per_splat, compact ? ", half precision" : "",
        static_cast<long long>(budget));

    StreamBenchResult result;
    result.file_pages = file.NumPages();
    result.pool_pages = pool_pages;
    result.pool_splats = pool_splats;
    result.bytes_per_splat = bytes_per_splat;
    result.compact_storage = compact;
    result.pool_ready_ms = core::MillisecondsSince(start);
    std::printf("stream: pool ready %.0f ms after the load started\n", result.pool_ready_ms);
    double first_ms = -1.0, first_db = 0.0, last_print = -1.0;
    rendering::SplatStreamStep step;
    rendering::RenderOutput frame;
    int steps = 0;
    for (; steps < 100000; ++steps) {
        // The first step reads the root's page alone: the first image as early as can be.
        const auto step_start = std::chrono::steady_clock::now();
        step = streamer.Step(rendering::SplatCutViewOf(camera),
                             steps == 0 ? 0 : options.reads_per_step);
        const double step_ms = core::MillisecondsSince(step_start);
        const auto write_start = std::chrono::steady_clock::now();
        backend->ApplyStreamStep(step);
        const double write_ms = core::MillisecondsSince(write_start);
        frame = backend->Render(camera, pool_config);
        const double ms = core::MillisecondsSince(start);
        if (first_ms < 0) {
            first_ms = ms;
            first_db =
                t::geometry::ComputeImageErrorMetrics(frame.color, exact, 1.0, 1.0 / 255.0).psnr_db;
        }
        const bool done = step.pages_wanted == 0 || (step.starved && step.writes.empty());
        if (done || ms - last_print >= 250.0 || steps == 0) {
            last_print = ms;
            std::printf(
                "stream step %d at %.0f ms: %lld pages in the pool, %lld read (%.2f GB), %lld "
                "evicted, cut %lld nodes (%.0f ms), %lld pages wanted%s, read %.0f ms (the step "
                "%.0f ms), written to the pool in %.0f ms, frame %.2f ms GPU\n",
                steps, ms, static_cast<long long>(streamer.ResidentPages()),
                static_cast<long long>(streamer.PagesRead()), streamer.BytesRead() / 1e9,
                static_cast<long long>(streamer.Evictions()),
                static_cast<long long>(step.cut_nodes), step.cut_ms,
                static_cast<long long>(step.pages_wanted), step.starved ? " (pool full)" : "",
                step.read_ms, step_ms, write_ms,
                frame.stats.gpu_project_ms + frame.stats.gpu_sort_ms +
                    frame.stats.gpu_composite_ms);
        }
        if (done) break;
    }
    const double converged_ms = core::MillisecondsSince(start);
    const auto m = t::geometry::ComputeImageErrorMetrics(frame.color, exact, 1.0, 1.0 / 255.0);
    std::printf(
        "stream: first image %.0f ms after the load started (%.1f dB), converged after %d steps "
        "in %.0f "
        "ms (%.2f GB read, %.0f MB/s); converged image against the exact render: %.1f dB, max "
        "%.3g, %.2f%% of pixels > 1/255\n",
        first_ms, first_db, steps + 1, converged_ms, streamer.BytesRead() / 1e9,
        streamer.BytesRead() / 1e6 / (converged_ms / 1e3), m.psnr_db, m.max_abs_error,
        100.0 * m.fraction_over_threshold);
    result.first_image_ms = first_ms;
    result.first_image_psnr_db = first_db;
    result.converged_ms = converged_ms;
    result.steps = steps + 1;
    result.pages_read = streamer.PagesRead();
    result.evictions = streamer.Evictions();
    result.bytes_read = streamer.BytesRead();
    result.cut_nodes = step.cut_nodes;
    result.pool_full = step.pages_wanted > 0;
    result.psnr_db = m.psnr_db;
    result.max_abs_error = m.max_abs_error;
    result.fraction_over_1_255 = m.fraction_over_threshold;
    return result;
}

}  // namespace bench
}  // namespace open3d
