// A 2D VkImage with its own memory allocation and one view (the images of the composite:
// colour, depths, alpha, merged depth, and test/placeholder depth textures), plus the image
// layout barrier helper. Images owned by someone else (Filament's shared depth) are passed
// as plain VkImageView values and never wrapped here.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <utility>

#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class VulkanContext;

using UniqueImage = UniqueDeviceHandle<VkImage, vkDestroyImage>;
using UniqueImageView = UniqueDeviceHandle<VkImageView, vkDestroyImageView>;

/// The aspect of a format's view: DEPTH for depth formats, COLOR otherwise.
VkImageAspectFlags AspectOf(VkFormat format);

class Image {
public:
    Image() = default;
    /// A width x height (both > 0) single-mip, single-layer, optimal-tiling image in device
    /// memory with a 2D view; the layout starts UNDEFINED. Throws core::Open3DError when
    /// the format does not support `usage` or the allocation fails.
    Image(const VulkanContext& context, uint32_t width, uint32_t height, VkFormat format,
          VkImageUsageFlags usage);

    Image(Image&&) noexcept = default;
    Image& operator=(Image&& other) noexcept {
        view_ = std::move(other.view_);  // view, image, memory: the destructor's order
        image_ = std::move(other.image_);
        memory_ = std::move(other.memory_);
        width_ = other.width_;
        height_ = other.height_;
        format_ = other.format_;
        return *this;
    }
    ~Image() = default;

    VkImage Get() const { return image_.Get(); }
    VkImageView GetView() const { return view_.Get(); }
    uint32_t GetWidth() const { return width_; }
    uint32_t GetHeight() const { return height_; }
    VkFormat GetFormat() const { return format_; }
    explicit operator bool() const { return static_cast<bool>(image_); }

private:
    // Destroyed in reverse order: view, image, then memory.
    UniqueDeviceMemory memory_;
    UniqueImage image_;
    UniqueImageView view_;
    uint32_t width_ = 0;
    uint32_t height_ = 0;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
};

/// One image memory barrier (synchronization2) over the whole image, with a layout change
/// (old == new for a plain memory dependency; UNDEFINED discards the contents).
void RecordImageBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                        VkImageLayout old_layout, VkImageLayout new_layout,
                        VkPipelineStageFlags2 src_stages, VkAccessFlags2 src_access,
                        VkPipelineStageFlags2 dst_stages, VkAccessFlags2 dst_access);

/// Records the upload of a depth texture from `staging` (one float per texel, row 0 first)
/// into `image` (D32_SFLOAT, created with TRANSFER_DST | SAMPLED), leaving it in
/// SHADER_READ_ONLY_OPTIMAL for compute-shader sampling.
void RecordDepthTextureUpload(VkCommandBuffer cmd, const Image& image, VkBuffer staging);

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
