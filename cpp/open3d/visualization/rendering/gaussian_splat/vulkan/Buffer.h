// A VkBuffer with its own memory allocation (written by hand: one allocation per buffer,
// which suits the few large buffers of the splat pipeline), and BufferRange, the
// non-owning view that recorders take so they work on buffers of any owner.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <utility>

#include "open3d/visualization/rendering/gaussian_splat/vulkan/DeviceMemoryBudget.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class VulkanContext;

/// A byte range of a buffer that someone else owns.
struct BufferRange {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    VkDeviceSize size = VK_WHOLE_SIZE;
    /// Device address of byte `offset` for a buffer made with
    /// VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT, else 0.
    VkDeviceAddress address = 0;
};

/// `range`'s device address as the shaders' push constants take it: low word, high word.
/// Throws core::Open3DError naming `what` unless its buffer was made with
/// VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT and the address is 16-byte aligned (the
/// shaders read 128-bit words there).
std::array<uint32_t, 2> DeviceAddressWords(const BufferRange& range, const char* what);

enum class MemoryUsage {
    /// GPU-only memory (DEVICE_LOCAL).
    kDevice,
    /// HOST_VISIBLE | HOST_COHERENT, persistently mapped: uploads and small parameters.
    kHostUpload,
    /// HOST_VISIBLE | HOST_COHERENT, preferably HOST_CACHED, persistently mapped: readback.
    kHostReadback,
};

class Buffer {
public:
    Buffer() = default;
    /// Creates a buffer of `size` bytes (> 0) with `usage` and binds fresh memory to it.
    /// Throws core::Open3DError when the allocation fails. With
    /// VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT in `usage` the memory is allocated for device
    /// addresses and GetDeviceAddress() returns the buffer's.
    /// With `shared_with_transfer` the buffer is usable from the context's transfer queue
    /// too (concurrent sharing of the two families, when the context has that queue).
    Buffer(const VulkanContext& context, VkDeviceSize size, VkBufferUsageFlags usage,
           MemoryUsage memory, bool shared_with_transfer = false);

    Buffer(Buffer&& other) noexcept
        : charge_(std::move(other.charge_)),
          memory_(std::move(other.memory_)),
          buffer_(std::move(other.buffer_)),
          size_(std::exchange(other.size_, 0)),
          address_(std::exchange(other.address_, 0)),
          mapped_(std::exchange(other.mapped_, nullptr)) {}
    Buffer& operator=(Buffer&& other) noexcept {
        buffer_ = std::move(other.buffer_);  // buffer before memory, as in the destructor
        memory_ = std::move(other.memory_);
        charge_ = std::move(other.charge_);  // after the memory it accounts for is freed
        size_ = std::exchange(other.size_, 0);
        address_ = std::exchange(other.address_, 0);
        mapped_ = std::exchange(other.mapped_, nullptr);
        return *this;
    }
    ~Buffer() = default;

    /// A buffer over `size` bytes of host memory at `data` that the caller allocated and
    /// keeps allocated while the buffer exists (VK_EXT_external_memory_host): device copies
    /// into the buffer land in that memory directly. `data` and `size` must be multiples of
    /// VulkanContext::GetHostImportAlignment(). Not charged to the device budget (the memory
    /// is the caller's). Throws core::Open3DError when the context cannot import it.
    static Buffer ImportHost(const VulkanContext& context, void* data, VkDeviceSize size,
                             VkBufferUsageFlags usage, bool shared_with_transfer = false);

    VkBuffer Get() const { return buffer_.Get(); }
    VkDeviceSize GetSize() const { return size_; }
    /// The buffer's device address; 0 unless made with VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT.
    VkDeviceAddress GetDeviceAddress() const { return address_; }
    /// The whole buffer, or [offset, offset + size).
    BufferRange Range(VkDeviceSize offset = 0, VkDeviceSize size = VK_WHOLE_SIZE) const;
    /// Host pointer of a kHostUpload / kHostReadback buffer, nullptr for kDevice.
    void* GetMapped() const { return mapped_; }
    explicit operator bool() const { return static_cast<bool>(buffer_); }

private:
    DeviceMemoryCharge charge_;  // given back after the memory is freed
    // Declared first so the buffer is destroyed before its memory is freed.
    UniqueDeviceMemory memory_;
    UniqueBuffer buffer_;
    VkDeviceSize size_ = 0;
    VkDeviceAddress address_ = 0;
    void* mapped_ = nullptr;  // unmapped implicitly by vkFreeMemory
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
