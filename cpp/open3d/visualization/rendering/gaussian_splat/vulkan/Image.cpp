#include "open3d/visualization/rendering/gaussian_splat/vulkan/Image.h"

#include <cmath>
#include <cstring>
#include <string>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/CommandTally.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

VkImageAspectFlags AspectOf(VkFormat format) {
    switch (format) {
        case VK_FORMAT_D16_UNORM:
        case VK_FORMAT_D32_SFLOAT:
        case VK_FORMAT_X8_D24_UNORM_PACK32:
            return VK_IMAGE_ASPECT_DEPTH_BIT;
        default:
            return VK_IMAGE_ASPECT_COLOR_BIT;
    }
}

namespace {

constexpr VkExternalMemoryHandleTypeFlagBits kExportHandleType =
    VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;

// Whether the device can make the image (and export its memory): asked first, so an
// unsupported format, usage or export becomes an actionable error rather than a validation
// message.
// "" when the device can create the image; else why not, in words a user can act on.
std::string WhyNotCreatable(const VulkanContext& context, const VkImageCreateInfo& info,
                            bool exportable) {
    VkPhysicalDeviceExternalImageFormatInfo external_info =
        MakeInfo<VkPhysicalDeviceExternalImageFormatInfo>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_IMAGE_FORMAT_INFO);
    external_info.handleType = kExportHandleType;
    VkPhysicalDeviceImageFormatInfo2 format_info = MakeInfo<VkPhysicalDeviceImageFormatInfo2>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_IMAGE_FORMAT_INFO_2);
    format_info.pNext = exportable ? &external_info : nullptr;
    format_info.format = info.format;
    format_info.type = info.imageType;
    format_info.tiling = info.tiling;
    format_info.usage = info.usage;
    VkExternalImageFormatProperties external = MakeInfo<VkExternalImageFormatProperties>(
        VK_STRUCTURE_TYPE_EXTERNAL_IMAGE_FORMAT_PROPERTIES);
    VkImageFormatProperties2 properties =
        MakeInfo<VkImageFormatProperties2>(VK_STRUCTURE_TYPE_IMAGE_FORMAT_PROPERTIES_2);
    properties.pNext = exportable ? &external : nullptr;
    if (vkGetPhysicalDeviceImageFormatProperties2(context.GetPhysicalDevice(), &format_info,
                                                  &properties) != VK_SUCCESS) {
        return "it does not support this format and usage";
    }
    if (exportable && (external.externalMemoryProperties.externalMemoryFeatures &
                       VK_EXTERNAL_MEMORY_FEATURE_EXPORTABLE_BIT) == 0) {
        return "it cannot export such an image's memory as an fd";
    }
    const VkExtent3D& max = properties.imageFormatProperties.maxExtent;
    if (max.width < info.extent.width || max.height < info.extent.height) {
        return fmt::format(
            "its largest image of this kind is {}x{}; render at most that size (or with the "
            "CPU backend, which has no such limit)",
            max.width, max.height);
    }
    return "";
}

}  // namespace

Image::Image(const VulkanContext& context, uint32_t width, uint32_t height, VkFormat format,
             VkImageUsageFlags usage, ImageMemory memory)
    : width_(width), height_(height), format_(format) {
    exportable_ = memory == ImageMemory::kExportableFd;
    if (exportable_ && !context.SupportsExternalMemoryFd()) {
        core::ThrowError("Vulkan: {} cannot export memory ({} is not enabled)",
                         context.GetDeviceInfo().name, VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
    }
    VkDevice device = context.GetDevice();
    VkExternalMemoryImageCreateInfo external_info = MakeInfo<VkExternalMemoryImageCreateInfo>(
        VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_IMAGE_CREATE_INFO);
    external_info.handleTypes = kExportHandleType;
    VkImageCreateInfo info = MakeInfo<VkImageCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO);
    info.pNext = exportable_ ? &external_info : nullptr;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {width, height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    if (const std::string why = WhyNotCreatable(context, info, exportable_); !why.empty()) {
        core::ThrowError("Vulkan: {} cannot make a {}x{} image (format {}, usage {:#x}{}): {}",
                         context.GetDeviceInfo().name, width, height, static_cast<int>(format),
                         static_cast<uint32_t>(usage), exportable_ ? ", exportable" : "", why);
    }
    VkImage image = VK_NULL_HANDLE;
    CheckVk(vkCreateImage(device, &info, nullptr, &image), "vkCreateImage");
    image_ = UniqueImage(device, image);

    VkMemoryRequirements requirements;
    vkGetImageMemoryRequirements(device, image, &requirements);
    // Exported memory is always a dedicated allocation (GL imports it with
    // GL_DEDICATED_MEMORY_OBJECT_EXT).
    VkMemoryDedicatedAllocateInfo dedicated =
        MakeInfo<VkMemoryDedicatedAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO);
    dedicated.image = image;
    VkExportMemoryAllocateInfo export_info =
        MakeInfo<VkExportMemoryAllocateInfo>(VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO);
    export_info.pNext = &dedicated;
    export_info.handleTypes = kExportHandleType;
    VkMemoryAllocateInfo allocate_info =
        MakeInfo<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    allocate_info.pNext = exportable_ ? &export_info : nullptr;
    allocate_info.allocationSize = requirements.size;
    allocate_info.memoryTypeIndex =
        context.FindMemoryType(requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    DeviceMemoryCharge charge =
        context.GetMemoryBudget().Charge(allocate_info.memoryTypeIndex, requirements.size,
                                         fmt::format("a {}x{} image", width, height));
    VkDeviceMemory device_memory = VK_NULL_HANDLE;
    VkResult result = vkAllocateMemory(device, &allocate_info, nullptr, &device_memory);
    if (result != VK_SUCCESS) {
        core::ThrowError("Vulkan: allocating {} KiB for a {}x{} image failed with {}",
                         requirements.size >> 10, width, height, VkResultName(result));
    }
    memory_ = UniqueDeviceMemory(device, device_memory);
    charge_ = std::move(charge);
    allocation_size_ = requirements.size;
    CheckVk(vkBindImageMemory(device, image, device_memory, 0), "vkBindImageMemory");

    VkImageViewCreateInfo view_info =
        MakeInfo<VkImageViewCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO);
    view_info.image = image;
    view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view_info.format = format;
    view_info.subresourceRange = {AspectOf(format), 0, 1, 0, 1};
    VkImageView view = VK_NULL_HANDLE;
    CheckVk(vkCreateImageView(device, &view_info, nullptr, &view), "vkCreateImageView");
    view_ = UniqueImageView(device, view);
}

ImageMemoryFd Image::ExportFd(const VulkanContext& context) const {
    if (!exportable_ || !context.SupportsExternalMemoryFd()) {
        core::ThrowError("Vulkan: this image was not created with exportable memory");
    }
    VkMemoryGetFdInfoKHR info =
        MakeInfo<VkMemoryGetFdInfoKHR>(VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR);
    info.memory = memory_.Get();
    info.handleType = kExportHandleType;
    int fd = -1;
    CheckVk(context.GetMemoryFd()(context.GetDevice(), &info, &fd), "vkGetMemoryFdKHR");
    return {fd, allocation_size_};
}

void RecordImageBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                        VkImageLayout old_layout, VkImageLayout new_layout,
                        VkPipelineStageFlags2 src_stages, VkAccessFlags2 src_access,
                        VkPipelineStageFlags2 dst_stages, VkAccessFlags2 dst_access,
                        uint32_t src_queue_family, uint32_t dst_queue_family) {
    VkImageMemoryBarrier2 barrier =
        MakeInfo<VkImageMemoryBarrier2>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2);
    barrier.srcStageMask = src_stages;
    barrier.srcAccessMask = src_access;
    barrier.dstStageMask = dst_stages;
    barrier.dstAccessMask = dst_access;
    barrier.oldLayout = old_layout;
    barrier.newLayout = new_layout;
    barrier.srcQueueFamilyIndex = src_queue_family;
    barrier.dstQueueFamilyIndex = dst_queue_family;
    barrier.image = image;
    barrier.subresourceRange = {aspect, 0, 1, 0, 1};
    VkDependencyInfo dependency = MakeInfo<VkDependencyInfo>(VK_STRUCTURE_TYPE_DEPENDENCY_INFO);
    dependency.imageMemoryBarrierCount = 1;
    dependency.pImageMemoryBarriers = &barrier;
    CommandTally::NoteBarrier();
    vkCmdPipelineBarrier2(cmd, &dependency);
}

void RecordCopyToBuffer(VkCommandBuffer cmd, const Image& image, VkImageLayout layout,
                        VkBuffer buffer, VkDeviceSize offset) {
    VkBufferImageCopy region{};
    region.bufferOffset = offset;
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {image.GetWidth(), image.GetHeight(), 1};
    vkCmdCopyImageToBuffer(cmd, image.Get(), layout, buffer, 1, &region);
}

float HalfToFloat(uint16_t bits) {
    const uint32_t sign = uint32_t(bits >> 15) << 31;
    const uint32_t exponent = (bits >> 10) & 0x1Fu;
    const uint32_t mantissa = bits & 0x3FFu;
    float magnitude;
    if (exponent == 0) {
        magnitude = std::ldexp(static_cast<float>(mantissa), -24);
    } else if (exponent == 31) {
        magnitude = mantissa ? NAN : INFINITY;
    } else {
        magnitude = std::ldexp(static_cast<float>(mantissa | 0x400u), int(exponent) - 25);
    }
    uint32_t result;
    std::memcpy(&result, &magnitude, 4);
    result |= sign;
    std::memcpy(&magnitude, &result, 4);
    return magnitude;
}

void RecordDepthTextureUpload(VkCommandBuffer cmd, const Image& image, VkBuffer staging) {
    RecordImageBarrier(cmd, image.Get(), VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE,
                       VK_ACCESS_2_NONE, VK_PIPELINE_STAGE_2_COPY_BIT,
                       VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
    region.imageExtent = {image.GetWidth(), image.GetHeight(), 1};
    vkCmdCopyBufferToImage(cmd, staging, image.Get(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                           &region);
    RecordImageBarrier(cmd, image.Get(), VK_IMAGE_ASPECT_DEPTH_BIT,
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                       VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                       VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                       VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
