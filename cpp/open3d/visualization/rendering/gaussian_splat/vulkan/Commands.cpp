#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"

#include "open3d/core/WaitCallback.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/CommandTally.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

void CommandBuffer::Begin(bool one_time_submit) const {
    VkCommandBufferBeginInfo info =
        MakeInfo<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
    info.flags = one_time_submit
                     ? VkCommandBufferUsageFlags(VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT)
                     : VkCommandBufferUsageFlags(0);
    CheckVk(vkBeginCommandBuffer(buffer_, &info), "vkBeginCommandBuffer");
}

void CommandBuffer::End() const { CheckVk(vkEndCommandBuffer(buffer_), "vkEndCommandBuffer"); }

void CommandBuffer::Reset() {
    if (buffer_ != VK_NULL_HANDLE) vkFreeCommandBuffers(device_, pool_, 1, &buffer_);
    buffer_ = VK_NULL_HANDLE;
}

CommandPool::CommandPool(const VulkanContext& context)
    : CommandPool(context, context.GetQueueFamilyIndex()) {}

CommandPool::CommandPool(const VulkanContext& context, uint32_t queue_family_index) {
    VkCommandPoolCreateInfo info =
        MakeInfo<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
    info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    info.queueFamilyIndex = queue_family_index;
    VkCommandPool pool = VK_NULL_HANDLE;
    CheckVk(vkCreateCommandPool(context.GetDevice(), &info, nullptr, &pool), "vkCreateCommandPool");
    pool_ = UniqueCommandPool(context.GetDevice(), pool);
}

CommandBuffer CommandPool::Allocate() const {
    VkCommandBufferAllocateInfo info =
        MakeInfo<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
    info.commandPool = pool_.Get();
    info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    info.commandBufferCount = 1;
    VkCommandBuffer buffer = VK_NULL_HANDLE;
    CheckVk(vkAllocateCommandBuffers(pool_.GetDevice(), &info, &buffer),
            "vkAllocateCommandBuffers");
    return CommandBuffer(pool_.GetDevice(), pool_.Get(), buffer);
}

UniqueFence CreateFence(const VulkanContext& context) {
    VkFenceCreateInfo info = MakeInfo<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
    VkFence fence = VK_NULL_HANDLE;
    CheckVk(vkCreateFence(context.GetDevice(), &info, nullptr, &fence), "vkCreateFence");
    return UniqueFence(context.GetDevice(), fence);
}

void Submit(const VulkanContext& context, VkCommandBuffer cmd, VkFence fence) {
    SubmitToQueue(context.GetQueue(), cmd, fence, VK_NULL_HANDLE, VK_PIPELINE_STAGE_2_NONE,
                  VK_NULL_HANDLE);
}

void SubmitToQueue(VkQueue queue, VkCommandBuffer cmd, VkFence fence, VkSemaphore wait,
                   VkPipelineStageFlags2 wait_stages, VkSemaphore signal) {
    VkCommandBufferSubmitInfo cmd_info =
        MakeInfo<VkCommandBufferSubmitInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO);
    cmd_info.commandBuffer = cmd;
    VkSemaphoreSubmitInfo wait_info =
        MakeInfo<VkSemaphoreSubmitInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO);
    wait_info.semaphore = wait;
    wait_info.stageMask = wait_stages;
    VkSemaphoreSubmitInfo signal_info =
        MakeInfo<VkSemaphoreSubmitInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO);
    signal_info.semaphore = signal;
    signal_info.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    VkSubmitInfo2 submit = MakeInfo<VkSubmitInfo2>(VK_STRUCTURE_TYPE_SUBMIT_INFO_2);
    submit.commandBufferInfoCount = 1;
    submit.pCommandBufferInfos = &cmd_info;
    submit.waitSemaphoreInfoCount = wait != VK_NULL_HANDLE ? 1u : 0u;
    submit.pWaitSemaphoreInfos = &wait_info;
    submit.signalSemaphoreInfoCount = signal != VK_NULL_HANDLE ? 1u : 0u;
    submit.pSignalSemaphoreInfos = &signal_info;
    CheckVk(vkQueueSubmit2(queue, 1, &submit, fence), "vkQueueSubmit2");
}

UniqueSemaphore CreateBinarySemaphore(const VulkanContext& context, bool exportable_fd) {
    VkSemaphoreCreateInfo info =
        MakeInfo<VkSemaphoreCreateInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO);
    VkExportSemaphoreCreateInfo export_info =
        MakeInfo<VkExportSemaphoreCreateInfo>(VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO);
    export_info.handleTypes = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
    if (exportable_fd) info.pNext = &export_info;
    VkSemaphore semaphore = VK_NULL_HANDLE;
    CheckVk(vkCreateSemaphore(context.GetDevice(), &info, nullptr, &semaphore),
            "vkCreateSemaphore");
    return UniqueSemaphore(context.GetDevice(), semaphore);
}

void Wait(const VulkanContext& context, VkFence fence) {
    if (!core::HasWaitCallback()) {
        CheckVk(vkWaitForFences(context.GetDevice(), 1, &fence, VK_TRUE, UINT64_MAX),
                "vkWaitForFences");
        return;
    }
    // In slices, with the thread's wait callback between them (the viewer polls events).
    constexpr uint64_t kSliceNs = uint64_t(core::kWaitCallbackPeriodMs) * 1000000u;
    for (;;) {
        const VkResult result = vkWaitForFences(context.GetDevice(), 1, &fence, VK_TRUE, kSliceNs);
        if (result == VK_SUCCESS) return;
        if (result != VK_TIMEOUT) CheckVk(result, "vkWaitForFences");
        core::CallWaitCallback();
    }
}

bool IsSignaled(const VulkanContext& context, VkFence fence) {
    const VkResult result = vkGetFenceStatus(context.GetDevice(), fence);
    if (result == VK_NOT_READY) return false;
    CheckVk(result, "vkGetFenceStatus");
    return true;
}

void ResetFence(const VulkanContext& context, VkFence fence) {
    CheckVk(vkResetFences(context.GetDevice(), 1, &fence), "vkResetFences");
}

void SubmitAndWait(const VulkanContext& context, const CommandPool& pool,
                   const std::function<void(VkCommandBuffer)>& record) {
    CommandBuffer cmd = pool.Allocate();
    cmd.Begin();
    record(cmd.Get());
    cmd.End();
    UniqueFence fence = CreateFence(context);
    Submit(context, cmd.Get(), fence.Get());
    Wait(context, fence.Get());
}

void RecordMemoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 src_stages,
                         VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stages,
                         VkAccessFlags2 dst_access) {
    VkMemoryBarrier2 barrier = MakeInfo<VkMemoryBarrier2>(VK_STRUCTURE_TYPE_MEMORY_BARRIER_2);
    barrier.srcStageMask = src_stages;
    barrier.srcAccessMask = src_access;
    barrier.dstStageMask = dst_stages;
    barrier.dstAccessMask = dst_access;
    VkDependencyInfo dependency = MakeInfo<VkDependencyInfo>(VK_STRUCTURE_TYPE_DEPENDENCY_INFO);
    dependency.memoryBarrierCount = 1;
    dependency.pMemoryBarriers = &barrier;
    CommandTally::NoteBarrier();
    vkCmdPipelineBarrier2(cmd, &dependency);
}

void RecordComputeToComputeAndIndirect(VkCommandBuffer cmd) {
    RecordMemoryBarrier(
        cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
        VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
        VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
            VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
}

void RecordComputeToCompute(VkCommandBuffer cmd) {
    RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                        VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT,
                        VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                        VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
