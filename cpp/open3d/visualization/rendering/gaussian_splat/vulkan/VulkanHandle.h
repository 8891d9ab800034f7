// Move-only owners of Vulkan objects created from a VkDevice (docs/DESIGN.md "Code rules"). Each
// destroys its handle exactly once; handles owned by someone else (a host application,
// Filament) are passed as plain Vk* values or BufferRange and never wrapped here.
#pragma once

#include <vulkan/vulkan.h>

#include <utility>

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

/// Owns one device-child handle and destroys it with `Destroy` (vkDestroyX / vkFreeMemory).
template <typename Handle, void (*Destroy)(VkDevice, Handle, const VkAllocationCallbacks*)>
class UniqueDeviceHandle {
public:
    UniqueDeviceHandle() = default;
    /// Takes ownership of `handle`, created from `device`.
    UniqueDeviceHandle(VkDevice device, Handle handle) : device_(device), handle_(handle) {}
    ~UniqueDeviceHandle() { Reset(); }

    UniqueDeviceHandle(const UniqueDeviceHandle&) = delete;
    UniqueDeviceHandle& operator=(const UniqueDeviceHandle&) = delete;
    UniqueDeviceHandle(UniqueDeviceHandle&& other) noexcept
        : device_(other.device_), handle_(std::exchange(other.handle_, VK_NULL_HANDLE)) {}
    UniqueDeviceHandle& operator=(UniqueDeviceHandle&& other) noexcept {
        if (this != &other) {
            Reset();
            device_ = other.device_;
            handle_ = std::exchange(other.handle_, VK_NULL_HANDLE);
        }
        return *this;
    }

    /// Destroys the handle now (no-op when empty).
    void Reset() {
        if (handle_ != VK_NULL_HANDLE) Destroy(device_, handle_, nullptr);
        handle_ = VK_NULL_HANDLE;
    }

    Handle Get() const { return handle_; }
    VkDevice GetDevice() const { return device_; }
    explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }

private:
    VkDevice device_ = VK_NULL_HANDLE;
    Handle handle_ = VK_NULL_HANDLE;
};

using UniqueBuffer = UniqueDeviceHandle<VkBuffer, vkDestroyBuffer>;
using UniqueDeviceMemory = UniqueDeviceHandle<VkDeviceMemory, vkFreeMemory>;
using UniqueCommandPool = UniqueDeviceHandle<VkCommandPool, vkDestroyCommandPool>;
using UniqueFence = UniqueDeviceHandle<VkFence, vkDestroyFence>;
using UniqueSemaphore = UniqueDeviceHandle<VkSemaphore, vkDestroySemaphore>;
using UniqueQueryPool = UniqueDeviceHandle<VkQueryPool, vkDestroyQueryPool>;
using UniqueShaderModule = UniqueDeviceHandle<VkShaderModule, vkDestroyShaderModule>;
using UniqueDescriptorSetLayout =
    UniqueDeviceHandle<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>;
using UniqueDescriptorPool = UniqueDeviceHandle<VkDescriptorPool, vkDestroyDescriptorPool>;
using UniquePipelineLayout = UniqueDeviceHandle<VkPipelineLayout, vkDestroyPipelineLayout>;
using UniquePipeline = UniqueDeviceHandle<VkPipeline, vkDestroyPipeline>;

/// A zeroed Vulkan struct with its sType set (a partial aggregate initialiser such as
/// `VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO}` trips -Wextra).
template <typename T>
T MakeInfo(VkStructureType type) {
    T info{};
    info.sType = type;
    return info;
}

/// Throws core::Open3DError naming `what` and the VkResult when `result` is not VK_SUCCESS.
void CheckVk(VkResult result, const char* what);

/// "VK_ERROR_OUT_OF_DEVICE_MEMORY" etc.
const char* VkResultName(VkResult result);

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
