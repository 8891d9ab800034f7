// The Vulkan instance, device and compute queue that every Vulkan object of the splat
// renderer is created from. No singleton: whoever needs one creates it and passes it on
// (tests make their own). It either owns its handles (headless) or borrows them from a
// host application, which then keeps them alive for the context's lifetime.
#pragma once

#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "open3d/visualization/rendering/gaussian_splat/vulkan/DeviceMemoryBudget.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class DebugMessenger;

struct VulkanContextOptions {
    /// Loads VK_LAYER_KHRONOS_validation and logs every message it sends (counted, see
    /// GetValidationMessageCounts). The environment variable OPEN3D_VULKAN_VALIDATION=1
    /// turns it on and =0 turns it off, whatever this says.
    bool enable_validation = false;
    /// Also asks the layer for synchronization validation (missing barriers); slower.
    bool enable_synchronization_validation = false;
    /// Uses the first suitable device whose name contains this text; empty picks the best
    /// (discrete > integrated > virtual > CPU). Env OPEN3D_VULKAN_DEVICE overrides it.
    std::string device_name_filter;
    /// Treats the device as if its maxComputeWorkGroupCount[0] were at most this (0: as
    /// reported). Every pass then lays out its workgroups in rows of at most this many
    /// (DispatchGridFor), as on a device at Vulkan's minimum of 65,535: tests run those
    /// layouts on small scenes with it.
    uint32_t max_workgroups_x = 0;
};

/// Handles owned by a host application that the context uses without destroying them.
/// The device must have been created with Vulkan 1.3, the features `maintenance4`,
/// `synchronization2`, `bufferDeviceAddress` and `shaderInt64` enabled and the extension
/// VK_KHR_push_descriptor.
struct BorrowedVulkanHandles {
    VkInstance instance = VK_NULL_HANDLE;
    VkPhysicalDevice physical_device = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    uint32_t queue_family_index = 0;  ///< a family with graphics and compute
    VkQueue queue = VK_NULL_HANDLE;   ///< a queue of that family
    /// The host created the device with VK_KHR_external_memory_fd (a context cannot ask a
    /// device which extensions it was created with): enables exporting image memory.
    bool external_memory_fd_enabled = false;
    /// The host created the device with VK_KHR_external_semaphore_fd: enables exporting
    /// semaphores (GL waits for none of ours; ours wait for GL's, docs/filament.md).
    bool external_semaphore_fd_enabled = false;
    /// The host created the device with VK_EXT_external_memory_host: enables importing
    /// BatchHostMemory (the device then copies batch colours straight into it).
    bool host_memory_import_enabled = false;
    /// Optional: a queue of a transfer-only family (copy engines) that readback copies may
    /// use beside `queue`; VK_NULL_HANDLE for none.
    VkQueue transfer_queue = VK_NULL_HANDLE;
    uint32_t transfer_queue_family_index = 0;
    /// As VulkanContextOptions::max_workgroups_x.
    uint32_t max_workgroups_x = 0;
};

/// What the device is, as reported in the log at creation.
struct VulkanDeviceInfo {
    std::string name;
    std::string type;         ///< "discrete GPU", "integrated GPU", "virtual GPU", "CPU", "other"
    std::string driver_name;  ///< e.g. "llvmpipe", "NVIDIA"
    std::string driver_info;  ///< e.g. "Mesa 22.3.6 (LLVM 15.0.6)"
    uint32_t api_version = 0;
    uint32_t vendor_id = 0;
    uint32_t subgroup_size = 0;              ///< default size in compute shaders
    uint32_t min_subgroup_size = 0;          ///< a SPIR-V 1.6 shader may run with any size in
    uint32_t max_subgroup_size = 0;          ///< [min, max]
    uint32_t max_compute_shared_memory = 0;  ///< bytes per workgroup
    uint64_t min_storage_buffer_offset_alignment = 0;  ///< bytes
    uint64_t max_storage_buffer_range = 0;             ///< bytes one storage binding may span
    /// maxComputeWorkGroupCount[0] of one dispatch (or VulkanContextOptions::max_workgroups_x
    /// where lower): passes past it lay their workgroups out in rows (DispatchGridFor).
    uint32_t max_compute_workgroups_x = 0;
    float timestamp_period_ns = 0.0f;  ///< 0 when timestamps are unsupported
    uint32_t queue_family_index = 0;
    /// VkPhysicalDeviceIDProperties: another API (GL) sharing memory with this device must
    /// report the same UUIDs.
    std::array<uint8_t, VK_UUID_SIZE> device_uuid{};
    std::array<uint8_t, VK_UUID_SIZE> driver_uuid{};
};

/// Validation messages seen since the context was created.
struct ValidationMessageCounts {
    uint64_t errors = 0;
    uint64_t warnings = 0;
    uint64_t infos = 0;  ///< info and verbose
    /// Errors and warnings: what a test must keep at zero.
    uint64_t Problems() const { return errors + warnings; }
};

/// An optional feature is on unless the environment variable `name` is "0" (the switches
/// OPEN3D_VULKAN_TRANSFER_QUEUE, OPEN3D_VULKAN_HOST_IMPORT, OPEN3D_VULKAN_COMPOSITE_TO_HOST).
bool EnvironmentSwitchOn(const char* name);

class VulkanContext {
public:
    /// Creates its own instance and device. Throws core::Open3DError with what to install
    /// or change when no loader, driver or suitable device exists, or when validation is
    /// requested but the layer is missing.
    static std::unique_ptr<VulkanContext> CreateHeadless(const VulkanContextOptions& options = {});
    /// Wraps a host application's handles without owning them. Throws core::Open3DError
    /// when the physical device lacks what the shaders need.
    static std::unique_ptr<VulkanContext> CreateFromBorrowed(const BorrowedVulkanHandles& handles);

    ~VulkanContext();
    VulkanContext(const VulkanContext&) = delete;
    VulkanContext& operator=(const VulkanContext&) = delete;
    VulkanContext(VulkanContext&&) = delete;
    VulkanContext& operator=(VulkanContext&&) = delete;

    VkInstance GetInstance() const { return instance_; }
    VkPhysicalDevice GetPhysicalDevice() const { return physical_device_; }
    VkDevice GetDevice() const { return device_; }
    VkQueue GetQueue() const { return queue_; }
    uint32_t GetQueueFamilyIndex() const { return info_.queue_family_index; }
    /// A queue of a transfer-only family (the copy engines) beside the compute queue, so
    /// that copies to host memory overlap compute work. Headless contexts create one when
    /// the device has such a family (NVIDIA does; lavapipe does not) unless the environment
    /// sets OPEN3D_VULKAN_TRANSFER_QUEUE=0; borrowed ones use the host's, if given.
    bool HasTransferQueue() const { return transfer_queue_ != VK_NULL_HANDLE; }
    VkQueue GetTransferQueue() const { return transfer_queue_; }
    uint32_t GetTransferQueueFamilyIndex() const { return transfer_family_; }
    const VulkanDeviceInfo& GetDeviceInfo() const { return info_; }
    /// False for a context made from borrowed handles.
    bool OwnsHandles() const { return owns_handles_; }

    bool IsValidationEnabled() const { return messenger_ != nullptr; }
    /// Messages of the validation layer so far (all zero when validation is off).
    ValidationMessageCounts GetValidationMessageCounts() const;

    /// Index of a memory type allowed by `type_bits` with all `required` properties,
    /// preferring one that also has `preferred`. Throws core::Open3DError when none fits.
    uint32_t FindMemoryType(uint32_t type_bits, VkMemoryPropertyFlags required,
                            VkMemoryPropertyFlags preferred = 0) const;
    /// What Buffers and Images of this context hold per heap; they charge it before each
    /// allocation (DeviceMemoryBudget.h).
    const DeviceMemoryBudget& GetMemoryBudget() const { return memory_budget_; }

    /// vkCmdPushDescriptorSetKHR of this device (an extension entry point).
    PFN_vkCmdPushDescriptorSetKHR GetCmdPushDescriptorSet() const { return push_descriptor_set_; }

    /// True when VK_KHR_external_memory_fd is enabled: headless contexts enable it whenever
    /// the device has it; borrowed ones when BorrowedVulkanHandles says the host did.
    bool SupportsExternalMemoryFd() const { return get_memory_fd_ != nullptr; }
    /// vkGetMemoryFdKHR of this device; nullptr unless SupportsExternalMemoryFd().
    PFN_vkGetMemoryFdKHR GetMemoryFd() const { return get_memory_fd_; }

    /// True when VK_KHR_external_semaphore_fd is enabled: headless contexts enable it with
    /// memory export whenever the device has both; borrowed ones when the host did.
    bool SupportsExternalSemaphoreFd() const { return get_semaphore_fd_ != nullptr; }
    /// vkGetSemaphoreFdKHR of this device; nullptr unless SupportsExternalSemaphoreFd().
    PFN_vkGetSemaphoreFdKHR GetSemaphoreFd() const { return get_semaphore_fd_; }

    /// True when VK_EXT_external_memory_host is enabled: host allocations can back buffers
    /// (a batch's colours copied by the device straight into the caller's memory). Headless
    /// contexts enable it whenever the device has it, unless the environment sets
    /// OPEN3D_VULKAN_HOST_IMPORT=0; borrowed ones when BorrowedVulkanHandles says the host did.
    bool CanImportHostMemory() const { return get_host_pointer_properties_ != nullptr; }
    /// minImportedHostPointerAlignment: imported pointers and sizes are multiples of it.
    uint64_t GetHostImportAlignment() const { return host_import_alignment_; }
    /// vkGetMemoryHostPointerPropertiesEXT; nullptr unless CanImportHostMemory().
    PFN_vkGetMemoryHostPointerPropertiesEXT GetMemoryHostPointerProperties() const {
        return get_host_pointer_properties_;
    }

    /// vkDeviceWaitIdle; for teardown and tests, not for frames.
    void WaitIdle() const;

private:
    VulkanContext();
    // VulkanContextOptions::max_workgroups_x (0: nothing changes).
    void LimitWorkgroupsX(uint32_t max_workgroups_x);
    // The optional device extensions a device is created (or was, when borrowed) with.
    struct OptionalExtensions {
        bool external_memory_fd = false;
        bool external_semaphore_fd = false;
        bool host_memory_import = false;
    };
    void InitDevice(VkPhysicalDevice physical_device, uint32_t queue_family_index,
                    const OptionalExtensions& optional,
                    std::optional<uint32_t> transfer_family = std::nullopt);
    void LoadDeviceFunctions(const OptionalExtensions& optional);
    void ReportDevice() const;

    bool owns_handles_ = false;
    // Declared before the instance: the messenger must outlive vkDestroyInstance, which
    // may still report (e.g. leaked objects).
    std::unique_ptr<DebugMessenger> messenger_;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    VkQueue transfer_queue_ = VK_NULL_HANDLE;
    uint32_t transfer_family_ = 0;
    VkPhysicalDeviceMemoryProperties memory_properties_{};
    DeviceMemoryBudget memory_budget_;
    PFN_vkCmdPushDescriptorSetKHR push_descriptor_set_ = nullptr;
    PFN_vkGetMemoryFdKHR get_memory_fd_ = nullptr;
    PFN_vkGetSemaphoreFdKHR get_semaphore_fd_ = nullptr;
    PFN_vkGetMemoryHostPointerPropertiesEXT get_host_pointer_properties_ = nullptr;
    uint64_t host_import_alignment_ = 0;
    VulkanDeviceInfo info_;
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
