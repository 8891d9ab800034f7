// Command pools, command buffers, fences and the barrier helper the recorders share.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <utility>

#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class VulkanContext;

/// A primary command buffer; freed back to its pool on destruction.
class CommandBuffer {
public:
    CommandBuffer() = default;
    CommandBuffer(VkDevice device, VkCommandPool pool, VkCommandBuffer buffer)
        : device_(device), pool_(pool), buffer_(buffer) {}
    ~CommandBuffer() { Reset(); }
    CommandBuffer(const CommandBuffer&) = delete;
    CommandBuffer& operator=(const CommandBuffer&) = delete;
    CommandBuffer(CommandBuffer&& other) noexcept
        : device_(other.device_),
          pool_(other.pool_),
          buffer_(std::exchange(other.buffer_, VK_NULL_HANDLE)) {}
    CommandBuffer& operator=(CommandBuffer&& other) noexcept {
        if (this != &other) {
            Reset();
            device_ = other.device_;
            pool_ = other.pool_;
            buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
        }
        return *this;
    }

    VkCommandBuffer Get() const { return buffer_; }
    /// vkBeginCommandBuffer, with ONE_TIME_SUBMIT unless the recording is submitted again.
    void Begin(bool one_time_submit = true) const;
    void End() const;

private:
    void Reset();

    VkDevice device_ = VK_NULL_HANDLE;
    VkCommandPool pool_ = VK_NULL_HANDLE;
    VkCommandBuffer buffer_ = VK_NULL_HANDLE;
};

/// A command pool of the context's queue family (not thread-safe, like every pool).
class CommandPool {
public:
    explicit CommandPool(const VulkanContext& context);
    /// A pool of another family of the device (the transfer queue's).
    CommandPool(const VulkanContext& context, uint32_t queue_family_index);
    /// A primary command buffer that can be reset and re-recorded.
    CommandBuffer Allocate() const;
    VkCommandPool Get() const { return pool_.Get(); }

private:
    UniqueCommandPool pool_;
};

/// An unsignaled fence.
UniqueFence CreateFence(const VulkanContext& context);

/// Submits one command buffer to the context's queue, signalling `fence` when done.
void Submit(const VulkanContext& context, VkCommandBuffer cmd, VkFence fence);

/// Submits one command buffer to `queue`: waits for `wait` (if any) before `wait_stages`,
/// signals `signal` (if any) and `fence` (if any) when done.
void SubmitToQueue(VkQueue queue, VkCommandBuffer cmd, VkFence fence, VkSemaphore wait,
                   VkPipelineStageFlags2 wait_stages, VkSemaphore signal);

/// A binary semaphore; with `exportable_fd`, one whose payload vkGetSemaphoreFdKHR can export
/// as an OPAQUE_FD (the context must support it).
UniqueSemaphore CreateBinarySemaphore(const VulkanContext& context, bool exportable_fd = false);

/// Waits for `fence` (no timeout: a hung GPU surfaces as VK_ERROR_DEVICE_LOST).
void Wait(const VulkanContext& context, VkFence fence);

/// Whether `fence` is signalled (no wait).
bool IsSignaled(const VulkanContext& context, VkFence fence);

/// Returns a signalled `fence` to unsignalled, for the next submission that reuses it.
void ResetFence(const VulkanContext& context, VkFence fence);

/// Records `record` into a fresh command buffer of `pool`, submits it and waits. For setup,
/// uploads and tests; frames submit without waiting.
void SubmitAndWait(const VulkanContext& context, const CommandPool& pool,
                   const std::function<void(VkCommandBuffer)>& record);

/// One global memory barrier (synchronization2).
void RecordMemoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 src_stages,
                         VkAccessFlags2 src_access, VkPipelineStageFlags2 dst_stages,
                         VkAccessFlags2 dst_access);

/// Compute writes before everything a later dispatch may read: storage data and the
/// arguments of indirect dispatches.
void RecordComputeToComputeAndIndirect(VkCommandBuffer cmd);

/// Compute writes before a later dispatch's storage reads and writes only: for dispatches whose
/// indirect arguments an earlier barrier already made visible (a lighter wait on some drivers).
void RecordComputeToCompute(VkCommandBuffer cmd);

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
