// A 2D VkImage with its own memory allocation and one view (the images of the composite:
// colour, depths, alpha, merged depth, and test/placeholder depth textures), plus the image
// layout barrier helper. Images owned by someone else are passed as plain VkImageView values
// and never wrapped here; images whose memory we export to GL (GaussianSplatInterop.h) are
// ours and are.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <utility>

#include "open3d/visualization/rendering/gaussian_splat/vulkan/DeviceMemoryBudget.h"
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

/// Where an image's memory may go.
enum class ImageMemory {
    /// Device memory of this process only.
    kLocal,
    /// A dedicated allocation exportable as a POSIX fd (OPAQUE_FD) for another API to import;
    /// needs VulkanContext::SupportsExternalMemoryFd().
    kExportableFd,
};

/// An exported allocation: a new descriptor the caller owns, and the allocation's size.
struct ImageMemoryFd {
    int fd = -1;
    VkDeviceSize size = 0;
};

class Image {
public:
    Image() = default;
    /// A width x height (both > 0) single-mip, single-layer, optimal-tiling image in device
    /// memory with a 2D view; the layout starts UNDEFINED. Throws core::Open3DError when
    /// the format does not support `usage` (or export, for kExportableFd) or the allocation
    /// fails.
    Image(const VulkanContext& context, uint32_t width, uint32_t height, VkFormat format,
          VkImageUsageFlags usage, ImageMemory memory = ImageMemory::kLocal);

    Image(Image&&) noexcept = default;
    Image& operator=(Image&& other) noexcept {
        view_ = std::move(other.view_);  // view, image, memory: the destructor's order
        image_ = std::move(other.image_);
        memory_ = std::move(other.memory_);
        charge_ = std::move(other.charge_);
        width_ = other.width_;
        height_ = other.height_;
        format_ = other.format_;
        allocation_size_ = other.allocation_size_;
        exportable_ = other.exportable_;
        return *this;
    }
    ~Image() = default;

    VkImage Get() const { return image_.Get(); }
    VkImageView GetView() const { return view_.Get(); }
    uint32_t GetWidth() const { return width_; }
    uint32_t GetHeight() const { return height_; }
    VkFormat GetFormat() const { return format_; }
    explicit operator bool() const { return static_cast<bool>(image_); }
    /// Bytes of the image's memory allocation.
    VkDeviceSize GetAllocationSize() const { return allocation_size_; }

    /// A new fd for the memory of a kExportableFd image (vkGetMemoryFdKHR, OPAQUE_FD); the
    /// caller owns it. Throws core::Open3DError for other images or when export fails.
    ImageMemoryFd ExportFd(const VulkanContext& context) const;

private:
    DeviceMemoryCharge charge_;  // given back after the memory is freed
    // Destroyed in reverse order: view, image, then memory.
    UniqueDeviceMemory memory_;
    UniqueImage image_;
    UniqueImageView view_;
    uint32_t width_ = 0;
    uint32_t height_ = 0;
    VkFormat format_ = VK_FORMAT_UNDEFINED;
    VkDeviceSize allocation_size_ = 0;
    bool exportable_ = false;
};

/// One image memory barrier (synchronization2) over the whole image, with a layout change
/// (old == new for a plain memory dependency; UNDEFINED discards the contents) and, when the
/// queue families differ, a queue-family ownership transfer.
void RecordImageBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                        VkImageLayout old_layout, VkImageLayout new_layout,
                        VkPipelineStageFlags2 src_stages, VkAccessFlags2 src_access,
                        VkPipelineStageFlags2 dst_stages, VkAccessFlags2 dst_access,
                        uint32_t src_queue_family = VK_QUEUE_FAMILY_IGNORED,
                        uint32_t dst_queue_family = VK_QUEUE_FAMILY_IGNORED);

/// Records the copy of a colour image (in `layout`: TRANSFER_SRC_OPTIMAL or GENERAL) into
/// `buffer` from `offset` on (a multiple of the texel size), tightly packed, row 0 first.
void RecordCopyToBuffer(VkCommandBuffer cmd, const Image& image, VkImageLayout layout,
                        VkBuffer buffer, VkDeviceSize offset = 0);

/// IEEE binary16 bits to float (exact), for reading back RGBA16F images.
float HalfToFloat(uint16_t bits);

/// Records the upload of a depth texture from `staging` (one float per texel, row 0 first)
/// into `image` (D32_SFLOAT, created with TRANSFER_DST | SAMPLED), leaving it in
/// SHADER_READ_ONLY_OPTIMAL for compute-shader sampling.
void RecordDepthTextureUpload(VkCommandBuffer cmd, const Image& image, VkBuffer staging);

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
