#include "open3d/visualization/rendering/gaussian_splat/vulkan/DeviceMemoryBudget.h"

#include <algorithm>
#include <cstdlib>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

VkDeviceSize LimitFromEnvironment() {
    const char* text = std::getenv("OPEN3D_DEVICE_MEMORY_LIMIT");
    if (text == nullptr || text[0] == '\0') return ~VkDeviceSize(0);
    char* end = nullptr;
    const unsigned long long value = std::strtoull(text, &end, 10);
    if (end == text || *end != '\0') {
        core::ThrowError("OPEN3D_DEVICE_MEMORY_LIMIT={}: expected a number of bytes", text);
    }
    return value;
}

}  // namespace

void DeviceMemoryCharge::Release() {
    if (budget_ != nullptr) budget_->used_[heap_] -= bytes_;
    budget_ = nullptr;
    bytes_ = 0;
}

VkDeviceSize DeviceMemoryBudget::Available(uint32_t heap) const {
    const VkDeviceSize limit = LimitFromEnvironment();
    const VkDeviceSize size =
        limit != ~VkDeviceSize(0) ? limit : properties_.memoryHeaps[heap].size;
    const VkDeviceSize used = used_[heap].load();
    return size > used ? size - used : 0;
}

DeviceMemoryCharge DeviceMemoryBudget::Charge(uint32_t memory_type, VkDeviceSize bytes,
                                              const std::string& what) const {
    const uint32_t heap = properties_.memoryTypes[memory_type].heapIndex;
    const VkDeviceSize available = Available(heap);
    if (bytes > available) {
        const bool limited = LimitFromEnvironment() != ~VkDeviceSize(0);
        core::ThrowError(
            "Vulkan: {} needs {} of device memory, {} is free (heap {}: {} by {}; this "
            "process holds {})",
            what, core::FormatBytes(bytes), core::FormatBytes(available), heap,
            core::FormatBytes(limited ? LimitFromEnvironment()
                                      : properties_.memoryHeaps[heap].size),
            limited ? "OPEN3D_DEVICE_MEMORY_LIMIT" : "the device's report",
            core::FormatBytes(used_[heap].load()));
    }
    used_[heap] += bytes;
    return DeviceMemoryCharge(this, heap, bytes);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
