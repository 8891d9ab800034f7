#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"

#include <cassert>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

Buffer::Buffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
               MemoryUsage memory, bool shared_with_transfer)
    : size_(size) {
    assert(size > 0 && "Vulkan buffers cannot be empty");
    VkDevice device = context.GetDevice();
    VkBufferCreateInfo buffer_info =
        MakeInfo<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    buffer_info.size = size;
    buffer_info.usage = usage;
    buffer_info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    const uint32_t families[2] = {context.GetQueueFamilyIndex(),
                                  context.GetTransferQueueFamilyIndex()};
    if (shared_with_transfer && context.HasTransferQueue() && families[0] != families[1]) {
        buffer_info.sharingMode = VK_SHARING_MODE_CONCURRENT;
        buffer_info.queueFamilyIndexCount = 2;
        buffer_info.pQueueFamilyIndices = families;
    }
    VkBuffer buffer = VK_NULL_HANDLE;
    CheckVk(vkCreateBuffer(device, &buffer_info, nullptr, &buffer), "vkCreateBuffer");
    buffer_ = UniqueBuffer(device, buffer);

    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(device, buffer, &requirements);
    VkMemoryPropertyFlags required = 0;
    VkMemoryPropertyFlags preferred = 0;
    switch (memory) {
        case MemoryUsage::kDevice:
            required = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
            break;
        case MemoryUsage::kHostUpload:
            required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
            break;
        case MemoryUsage::kHostReadback:
            required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
            preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
            break;
    }
    VkMemoryAllocateInfo allocate_info =
        MakeInfo<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    allocate_info.allocationSize = requirements.size;
    allocate_info.memoryTypeIndex =
        context.FindMemoryType(requirements.memoryTypeBits, required, preferred);
    DeviceMemoryCharge charge = context.GetMemoryBudget().Charge(
        allocate_info.memoryTypeIndex, requirements.size,
        memory == MemoryUsage::kDevice ? "a device buffer" : "a host-visible buffer");
    VkDeviceMemory device_memory = VK_NULL_HANDLE;
    VkResult result = vkAllocateMemory(device, &allocate_info, nullptr, &device_memory);
    if (result != VK_SUCCESS) {
        core::ThrowError(
            "Vulkan: allocating {} MiB of {} memory failed with {}", requirements.size >> 20,
            memory == MemoryUsage::kDevice ? "device" : "host-visible", VkResultName(result));
    }
    memory_ = UniqueDeviceMemory(device, device_memory);
    charge_ = std::move(charge);
    CheckVk(vkBindBufferMemory(device, buffer, device_memory, 0), "vkBindBufferMemory");
    if (memory != MemoryUsage::kDevice) {
        CheckVk(vkMapMemory(device, device_memory, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
    }
}

BufferRange Buffer::Range(VkDeviceSize offset, VkDeviceSize size) const {
    assert(offset <= size_);
    return BufferRange{buffer_.Get(), offset, size == VK_WHOLE_SIZE ? size_ - offset : size};
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
