#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"

#include <cassert>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

// A buffer of `size` bytes, shared with the transfer queue's family when asked and present;
// `next` extends the create info (external memory).
UniqueBuffer CreateBuffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
                          bool shared_with_transfer, const void* next = nullptr) {
    VkDevice device = context.GetDevice();
    VkBufferCreateInfo buffer_info =
        MakeInfo<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    buffer_info.pNext = next;
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
    return UniqueBuffer(device, buffer);
}

}  // namespace

Buffer::Buffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
               MemoryUsage memory, bool shared_with_transfer)
    : size_(size) {
    assert(size > 0 && "Vulkan buffers cannot be empty");
    VkDevice device = context.GetDevice();
    buffer_ = CreateBuffer(context, size, usage, shared_with_transfer);
    VkBuffer buffer = buffer_.Get();

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
    VkMemoryAllocateFlagsInfo flags_info =
        MakeInfo<VkMemoryAllocateFlagsInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO);
    const bool addressed = (usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) != 0;
    if (addressed) {
        flags_info.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        allocate_info.pNext = &flags_info;
    }
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
    if (addressed) {
        VkBufferDeviceAddressInfo address_info =
            MakeInfo<VkBufferDeviceAddressInfo>(VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO);
        address_info.buffer = buffer;
        address_ = vkGetBufferDeviceAddress(device, &address_info);
    }
    if (memory != MemoryUsage::kDevice) {
        CheckVk(vkMapMemory(device, device_memory, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
    }
}

Buffer Buffer::ImportHost(const VulkanContext& context, void* data, VkDeviceSize size,
                          VkBufferUsageFlags usage, bool shared_with_transfer) {
    const uint64_t alignment = context.GetHostImportAlignment();
    if (!context.CanImportHostMemory() || alignment == 0) {
        core::ThrowError("Vulkan: this context cannot import host memory ({} is not enabled)",
                         VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME);
    }
    if (size == 0 || reinterpret_cast<uintptr_t>(data) % alignment != 0 || size % alignment != 0) {
        core::ThrowError(
            "Vulkan: host memory to import must start and end at multiples of {} bytes (it "
            "is {} bytes at {})",
            alignment, size, data);
    }
    VkDevice device = context.GetDevice();
    constexpr VkExternalMemoryHandleTypeFlagBits kHandle =
        VK_EXTERNAL_MEMORY_HANDLE_TYPE_HOST_ALLOCATION_BIT_EXT;
    VkMemoryHostPointerPropertiesEXT pointer_properties =
        MakeInfo<VkMemoryHostPointerPropertiesEXT>(
            VK_STRUCTURE_TYPE_MEMORY_HOST_POINTER_PROPERTIES_EXT);
    CheckVk(context.GetMemoryHostPointerProperties()(device, kHandle, data, &pointer_properties),
            "vkGetMemoryHostPointerPropertiesEXT");
    VkExternalMemoryBufferCreateInfo external = MakeInfo<VkExternalMemoryBufferCreateInfo>(
        VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_BUFFER_CREATE_INFO);
    external.handleTypes = kHandle;
    Buffer result;
    result.buffer_ = CreateBuffer(context, size, usage, shared_with_transfer, &external);
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(device, result.buffer_.Get(), &requirements);
    VkImportMemoryHostPointerInfoEXT import = MakeInfo<VkImportMemoryHostPointerInfoEXT>(
        VK_STRUCTURE_TYPE_IMPORT_MEMORY_HOST_POINTER_INFO_EXT);
    import.handleType = kHandle;
    import.pHostPointer = data;
    VkMemoryAllocateInfo allocate_info =
        MakeInfo<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    allocate_info.pNext = &import;
    allocate_info.allocationSize = size;
    allocate_info.memoryTypeIndex = context.FindMemoryType(
        requirements.memoryTypeBits & pointer_properties.memoryTypeBits,
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
        VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
    VkDeviceMemory device_memory = VK_NULL_HANDLE;
    const VkResult imported = vkAllocateMemory(device, &allocate_info, nullptr, &device_memory);
    if (imported != VK_SUCCESS) {
        core::ThrowError("Vulkan: importing {} MiB of host memory failed with {}", size >> 20,
                         VkResultName(imported));
    }
    result.memory_ = UniqueDeviceMemory(device, device_memory);
    CheckVk(vkBindBufferMemory(device, result.buffer_.Get(), device_memory, 0),
            "vkBindBufferMemory");
    result.size_ = size;
    result.mapped_ = data;  // the caller's memory: never mapped through Vulkan
    return result;
}

std::array<uint32_t, 2> DeviceAddressWords(const BufferRange& range, const char* what) {
    if (range.address == 0 || range.address % 16 != 0) {
        core::ThrowError(
            "{} need a buffer made for device addresses "
            "(VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) at a 16-byte aligned address",
            what);
    }
    return {static_cast<uint32_t>(range.address), static_cast<uint32_t>(range.address >> 32)};
}

BufferRange Buffer::Range(VkDeviceSize offset, VkDeviceSize size) const {
    assert(offset <= size_);
    return BufferRange{buffer_.Get(), offset, size == VK_WHOLE_SIZE ? size_ - offset : size,
                       address_ != 0 ? address_ + offset : 0};
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
