#include "open3d/visualization/rendering/gaussian_splat/vulkan/Image.h"

#include "open3d/core/Exception.h"
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

Image::Image(const VulkanContext& context, uint32_t width, uint32_t height, VkFormat format,
             VkImageUsageFlags usage)
    : width_(width), height_(height), format_(format) {
    VkDevice device = context.GetDevice();
    VkImageCreateInfo info = MakeInfo<VkImageCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO);
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
    // Ask first, so an unsupported format/usage becomes an actionable error rather than a
    // validation message.
    VkImageFormatProperties properties{};
    if (vkGetPhysicalDeviceImageFormatProperties(context.GetPhysicalDevice(), format,
                                                 info.imageType, info.tiling, usage, 0,
                                                 &properties) != VK_SUCCESS ||
        properties.maxExtent.width < width || properties.maxExtent.height < height) {
        core::ThrowError("Vulkan: {} cannot hold a {}x{} image of format {} with usage {:#x}",
                         context.GetDeviceInfo().name, width, height, static_cast<int>(format),
                         static_cast<uint32_t>(usage));
    }
    VkImage image = VK_NULL_HANDLE;
    CheckVk(vkCreateImage(device, &info, nullptr, &image), "vkCreateImage");
    image_ = UniqueImage(device, image);

    VkMemoryRequirements requirements;
    vkGetImageMemoryRequirements(device, image, &requirements);
    VkMemoryAllocateInfo allocate_info =
        MakeInfo<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    allocate_info.allocationSize = requirements.size;
    allocate_info.memoryTypeIndex =
        context.FindMemoryType(requirements.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkResult result = vkAllocateMemory(device, &allocate_info, nullptr, &memory);
    if (result != VK_SUCCESS) {
        core::ThrowError("Vulkan: allocating {} KiB for a {}x{} image failed with {}",
                         requirements.size >> 10, width, height, VkResultName(result));
    }
    memory_ = UniqueDeviceMemory(device, memory);
    CheckVk(vkBindImageMemory(device, image, memory, 0), "vkBindImageMemory");

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

void RecordImageBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                        VkImageLayout old_layout, VkImageLayout new_layout,
                        VkPipelineStageFlags2 src_stages, VkAccessFlags2 src_access,
                        VkPipelineStageFlags2 dst_stages, VkAccessFlags2 dst_access) {
    VkImageMemoryBarrier2 barrier =
        MakeInfo<VkImageMemoryBarrier2>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2);
    barrier.srcStageMask = src_stages;
    barrier.srcAccessMask = src_access;
    barrier.dstStageMask = dst_stages;
    barrier.dstAccessMask = dst_access;
    barrier.oldLayout = old_layout;
    barrier.newLayout = new_layout;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {aspect, 0, 1, 0, 1};
    VkDependencyInfo dependency = MakeInfo<VkDependencyInfo>(VK_STRUCTURE_TYPE_DEPENDENCY_INFO);
    dependency.imageMemoryBarrierCount = 1;
    dependency.pImageMemoryBarriers = &barrier;
    vkCmdPipelineBarrier2(cmd, &dependency);
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
