// Device memory accounting of one VulkanContext, so that an allocation that cannot fit is
// refused with the numbers (docs/memory.md) instead of failing inside the driver with
// VK_ERROR_OUT_OF_DEVICE_MEMORY, or succeeding past the heap's size (lavapipe reports a
// 2 GiB heap and does not enforce it). Each heap's room is its size, or
// OPEN3D_DEVICE_MEMORY_LIMIT (bytes) where set: lower, for tests and to leave room to other
// programs; higher, to use more of the system memory a CPU device such as lavapipe
// allocates from. Where the device reports VK_EXT_memory_budget, at most its heapBudget at
// context creation (memory other processes and the driver hold is then out of the room).
// Less what this context's Buffers and Images hold.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <utility>

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class DeviceMemoryBudget;

/// Bytes of one heap held by one allocation; given back when destroyed.
class DeviceMemoryCharge {
public:
    DeviceMemoryCharge() = default;
    DeviceMemoryCharge(const DeviceMemoryBudget* budget, uint32_t heap, VkDeviceSize bytes)
        : budget_(budget), heap_(heap), bytes_(bytes) {}
    DeviceMemoryCharge(DeviceMemoryCharge&& other) noexcept
        : budget_(std::exchange(other.budget_, nullptr)),
          heap_(other.heap_),
          bytes_(std::exchange(other.bytes_, 0)) {}
    DeviceMemoryCharge& operator=(DeviceMemoryCharge&& other) noexcept {
        if (this != &other) {
            Release();
            budget_ = std::exchange(other.budget_, nullptr);
            heap_ = other.heap_;
            bytes_ = std::exchange(other.bytes_, 0);
        }
        return *this;
    }
    ~DeviceMemoryCharge() { Release(); }

private:
    void Release();
    const DeviceMemoryBudget* budget_ = nullptr;
    uint32_t heap_ = 0;
    VkDeviceSize bytes_ = 0;
};

class DeviceMemoryBudget {
public:
    /// `budgets`: VK_EXT_memory_budget's heapBudget at context creation where the device
    /// reports one (what this process may allocate of each heap), else null.
    void Init(const VkPhysicalDeviceMemoryProperties& properties,
              const std::array<VkDeviceSize, VK_MAX_MEMORY_HEAPS>* budgets = nullptr) {
        properties_ = properties;
        if (budgets != nullptr) reported_budgets_ = *budgets;
        have_reported_budgets_ = budgets != nullptr;
    }
    /// Bytes of `heap` still free to this context.
    VkDeviceSize Available(uint32_t heap) const;
    uint32_t HeapOf(uint32_t memory_type) const {
        return properties_.memoryTypes[memory_type].heapIndex;
    }
    /// Takes `bytes` of the heap behind `memory_type` for an allocation about to be made,
    /// or throws core::Open3DError: "Vulkan: {what} needs {bytes} of device memory, {free}
    /// of the {size} heap is free...".
    DeviceMemoryCharge Charge(uint32_t memory_type, VkDeviceSize bytes,
                              const std::string& what) const;

private:
    friend class DeviceMemoryCharge;
    /// The room of `heap` before this context's charges: its size, the device's budget
    /// where it reports one (the lower), or OPEN3D_DEVICE_MEMORY_LIMIT where set.
    VkDeviceSize Room(uint32_t heap, const char** source) const;

    VkPhysicalDeviceMemoryProperties properties_{};
    std::array<VkDeviceSize, VK_MAX_MEMORY_HEAPS> reported_budgets_{};
    bool have_reported_budgets_ = false;
    mutable std::array<std::atomic<VkDeviceSize>, VK_MAX_MEMORY_HEAPS> used_{};
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
