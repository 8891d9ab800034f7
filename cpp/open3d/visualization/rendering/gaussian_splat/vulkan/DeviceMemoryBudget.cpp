#include "open3d/visualization/rendering/gaussian_splat/vulkan/DeviceMemoryBudget.h"

#include <optional>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

std::optional<uint64_t> LimitFromEnvironment() {
    return core::ReadByteCountVariable("OPEN3D_DEVICE_MEMORY_LIMIT");
}

}  // namespace

void DeviceMemoryCharge::Release() {
    if (budget_ != nullptr) budget_->used_[heap_] -= bytes_;
    budget_ = nullptr;
    bytes_ = 0;
}

VkDeviceSize DeviceMemoryBudget::Room(uint32_t heap, const char** source) const {
    if (const std::optional<uint64_t> limit = LimitFromEnvironment()) {
        *source = "OPEN3D_DEVICE_MEMORY_LIMIT";
        return *limit;
    }
    const VkDeviceSize size = properties_.memoryHeaps[heap].size;
    if (have_reported_budgets_ && reported_budgets_[heap] > 0 && reported_budgets_[heap] < size) {
        *source = "the device's memory budget";
        return reported_budgets_[heap];
    }
    *source = "the device's report";
    return size;
}

VkDeviceSize DeviceMemoryBudget::Available(uint32_t heap) const {
    const char* source = nullptr;
    const VkDeviceSize size = Room(heap, &source);
    const VkDeviceSize used = used_[heap].load();
    return size > used ? size - used : 0;
}

DeviceMemoryCharge DeviceMemoryBudget::Charge(uint32_t memory_type, VkDeviceSize bytes,
                                              const std::string& what) const {
    const uint32_t heap = HeapOf(memory_type);
    const VkDeviceSize available = Available(heap);
    if (bytes > available) {
        const char* source = nullptr;
        const VkDeviceSize room = Room(heap, &source);
        core::ThrowError(
            "Vulkan: {} needs {} of device memory, {} is free (heap {}: {} by {}; this "
            "process holds {})",
            what, core::FormatBytes(bytes), core::FormatBytes(available), heap,
            core::FormatBytes(room), source, core::FormatBytes(used_[heap].load()));
    }
    used_[heap] += bytes;
    return DeviceMemoryCharge(this, heap, bytes);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
