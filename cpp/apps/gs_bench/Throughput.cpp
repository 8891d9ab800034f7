#include "Throughput.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <deque>

#include "open3d/core/Timer.h"
#include "open3d/visualization/rendering/gaussian_splat/BatchHostMemory.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"

namespace open3d {
namespace bench {

using visualization::rendering::BatchOptions;
using visualization::rendering::RenderConfig;
using visualization::rendering::vulkan::GaussianSplatVulkanBackend;

double PipelinedMsPerFrame(GaussianSplatVulkanBackend& backend,
                           const std::vector<camera::PinholeCamera>& cameras,
                           const RenderConfig& config, const BatchOptions& options, int frames) {
    const size_t depth = static_cast<size_t>(backend.GetFramesInFlight());
    std::deque<uint64_t> tickets;
    const auto run = [&](int count) {
        for (int i = 0; i < count; ++i) {
            if (tickets.size() == depth) {
                backend.WaitBatch(tickets.front());
                tickets.pop_front();
            }
            tickets.push_back(backend.SubmitBatch({cameras[i % cameras.size()]}, config, options));
        }
        while (!tickets.empty()) {
            backend.WaitBatch(tickets.front());
            tickets.pop_front();
        }
    };
    run(static_cast<int>(2 * depth));  // every slot recorded before the clock starts
    const auto start = std::chrono::steady_clock::now();
    run(frames);
    return core::MillisecondsSince(start) / frames;
}

BatchThroughput MeasureBatch(GaussianSplatVulkanBackend& backend,
                             const std::vector<camera::PinholeCamera>& cameras,
                             const RenderConfig& config, const BatchOptions& options, int batch,
                             int repeats, double warm_up_seconds) {
    std::vector<camera::PinholeCamera> views;
    for (int i = 0; i < batch; ++i) views.push_back(cameras[i % cameras.size()]);
    // Records, allocates, and brings the clocks up (they fall while the host alone works).
    const auto warm = std::chrono::steady_clock::now();
    do {
        backend.RenderBatch(views, config, options);
    } while (core::MillisecondsSince(warm) < 1000.0 * warm_up_seconds);
    BatchThroughput result;
    double gpu_ms = 0.0;
    const auto start = std::chrono::steady_clock::now();
    for (int r = 0; r < repeats; ++r) {
        backend.RenderBatch(views, config, options);
        gpu_ms += std::max(0.0, backend.GetLastBatchStats().gpu_ms);
        result.submissions_per_batch = backend.GetLastBatchStats().submissions;
    }
    const double wall_ms = core::MillisecondsSince(start);
    result.views_per_second = 1000.0 * batch * repeats / wall_ms;
    result.gpu_ms_per_view = gpu_ms / (double(batch) * repeats);
    return result;
}

double MeasureDeviceToHostGBs(const visualization::rendering::vulkan::VulkanContext& context,
                              uint64_t bytes, int repeats) {
    namespace vk = visualization::rendering::vulkan;
    const uint64_t alignment = context.GetHostImportAlignment();
    if (!context.CanImportHostMemory() || alignment == 0) return 0.0;
    visualization::rendering::BatchHostMemory host(static_cast<size_t>(bytes));
    if (reinterpret_cast<uintptr_t>(host.Data()) % alignment != 0 || host.Size() % alignment != 0) {
        return 0.0;
    }
    const bool transfer = context.HasTransferQueue();
    vk::Buffer device(context, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryUsage::kDevice,
                      /*shared_with_transfer=*/true);
    vk::Buffer target =
        vk::Buffer::ImportHost(context, host.Data(), host.Size(), VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                               /*shared_with_transfer=*/true);
    const vk::CommandPool pool(
        context, transfer ? context.GetTransferQueueFamilyIndex() : context.GetQueueFamilyIndex());
    const vk::CommandBuffer cmd = pool.Allocate();
    cmd.Begin(/*one_time_submit=*/false);
    const VkBufferCopy region{0, 0, bytes};
    vkCmdCopyBuffer(cmd.Get(), device.Get(), target.Get(), 1, &region);
    cmd.End();
    const VkQueue queue = transfer ? context.GetTransferQueue() : context.GetQueue();
    vk::UniqueFence fence = vk::CreateFence(context);
    const auto copy = [&] {
        vk::SubmitToQueue(queue, cmd.Get(), fence.Get(), VK_NULL_HANDLE, VK_PIPELINE_STAGE_2_NONE,
                          VK_NULL_HANDLE);
        vk::Wait(context, fence.Get());
        vk::ResetFence(context, fence.Get());
    };
    copy();  // maps the pages for the device
    const auto start = std::chrono::steady_clock::now();
    for (int r = 0; r < repeats; ++r) copy();
    return double(bytes) * repeats / (core::MillisecondsSince(start) * 1e6);
}

std::string ReadGpuClockMHz() {
    FILE* pipe = popen(
        "nvidia-smi --query-gpu=clocks.sm,clocks.max.sm --format=csv,noheader,nounits "
        "2>/dev/null",
        "r");
    if (pipe == nullptr) return "";
    char line[128] = {0};
    const bool read = std::fgets(line, sizeof(line), pipe) != nullptr;
    pclose(pipe);
    if (!read) return "";
    unsigned current = 0, max = 0;
    if (std::sscanf(line, "%u, %u", &current, &max) != 2) return "";
    return std::to_string(current) + "/" + std::to_string(max);
}

}  // namespace bench
}  // namespace open3d
