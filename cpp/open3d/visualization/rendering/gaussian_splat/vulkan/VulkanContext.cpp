#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <optional>
#include <string_view>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/DebugMessenger.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

// An entry point of an enabled device extension; a missing one means the device was not
// created with the extension it was reported to have.
template <typename T>
void LoadExtensionFunction(VkDevice device, const char* name, const char* extension, T& function) {
    function = reinterpret_cast<T>(vkGetDeviceProcAddr(device, name));
    if (function == nullptr) {
        core::ThrowError("Vulkan: {} is unavailable although {} was reported enabled", name,
                         extension);
    }
}

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr uint32_t kRequiredApiVersion = VK_API_VERSION_1_3;
// What the compute shaders use: scans and reductions (arithmetic), subgroupElect (basic),
// ballots and shuffles (ballot/shuffle, for the projection and composite shaders).
constexpr VkSubgroupFeatureFlags kRequiredSubgroupOps =
    VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_ARITHMETIC_BIT |
    VK_SUBGROUP_FEATURE_BALLOT_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_BIT;
constexpr const char* kRequiredDeviceExtensions[] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};

const char* kInstallHint =
    "Install a Vulkan 1.3 driver (Debian: mesa-vulkan-drivers gives the lavapipe CPU "
    "device) and check the output of `vulkaninfo --summary`";

std::optional<std::string> GetEnv(const char* name) {
    const char* value = std::getenv(name);
    if (value == nullptr) return std::nullopt;
    return std::string(value);
}

std::string VersionString(uint32_t version) {
    return fmt::format("{}.{}.{}", VK_API_VERSION_MAJOR(version), VK_API_VERSION_MINOR(version),
                       VK_API_VERSION_PATCH(version));
}

const char* DeviceTypeName(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return "discrete GPU";
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return "integrated GPU";
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return "virtual GPU";
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return "CPU";
        default:
            return "other";
    }
}

int DeviceTypeRank(VkPhysicalDeviceType type) {
    switch (type) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return 4;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return 3;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return 1;
        default:
            return 0;
    }
}

bool HasInstanceLayer(const char* name) {
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    for (const auto& layer : layers) {
        if (std::strcmp(layer.layerName, name) == 0) return true;
    }
    return false;
}

bool HasInstanceExtension(const char* name) {
    uint32_t count = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vkEnumerateInstanceExtensionProperties(nullptr, &count, extensions.data());
    for (const auto& extension : extensions) {
        if (std::strcmp(extension.extensionName, name) == 0) return true;
    }
    return false;
}

/// Everything queried about one physical device.
struct DeviceQuery {
    VkPhysicalDeviceProperties2 properties =
        MakeInfo<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    VkPhysicalDeviceSubgroupProperties subgroup = MakeInfo<VkPhysicalDeviceSubgroupProperties>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES);
    VkPhysicalDeviceSubgroupSizeControlProperties size_control =
        MakeInfo<VkPhysicalDeviceSubgroupSizeControlProperties>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_SIZE_CONTROL_PROPERTIES);
    VkPhysicalDeviceDriverProperties driver = MakeInfo<VkPhysicalDeviceDriverProperties>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
    VkPhysicalDeviceIDProperties ids =
        MakeInfo<VkPhysicalDeviceIDProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES);
    VkPhysicalDeviceFeatures2 features =
        MakeInfo<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
    VkPhysicalDeviceVulkan12Features features12 = MakeInfo<VkPhysicalDeviceVulkan12Features>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
    VkPhysicalDeviceVulkan13Features features13 = MakeInfo<VkPhysicalDeviceVulkan13Features>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES);
    std::vector<VkQueueFamilyProperties> queue_families;
    std::vector<VkExtensionProperties> extensions;

    explicit DeviceQuery(VkPhysicalDevice device) {
        properties.pNext = &subgroup;
        subgroup.pNext = &size_control;
        size_control.pNext = &driver;
        driver.pNext = &ids;
        vkGetPhysicalDeviceProperties2(device, &properties);
        features.pNext = &features12;
        features12.pNext = &features13;
        vkGetPhysicalDeviceFeatures2(device, &features);
        uint32_t count = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
        queue_families.resize(count);
        vkGetPhysicalDeviceQueueFamilyProperties(device, &count, queue_families.data());
        count = 0;
        vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
        extensions.resize(count);
        vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
    }

    bool HasExtension(const char* name) const {
        for (const auto& extension : extensions) {
            if (std::strcmp(extension.extensionName, name) == 0) return true;
        }
        return false;
    }

    std::optional<uint32_t> FindQueueFamily() const {
        constexpr VkQueueFlags kNeeded = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
        for (uint32_t i = 0; i < queue_families.size(); ++i) {
            if ((queue_families[i].queueFlags & kNeeded) == kNeeded) return i;
        }
        return std::nullopt;
    }

    /// A family that copies but neither draws nor computes: NVIDIA's copy engines.
    std::optional<uint32_t> FindTransferFamily() const {
        constexpr VkQueueFlags kOther = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
        for (uint32_t i = 0; i < queue_families.size(); ++i) {
            const VkQueueFlags flags = queue_families[i].queueFlags;
            if ((flags & VK_QUEUE_TRANSFER_BIT) && !(flags & kOther)) return i;
        }
        return std::nullopt;
    }

    /// Empty when the device can run the shaders, otherwise why not.
    std::string WhyUnsuitable() const {
        std::vector<std::string> missing;
        if (properties.properties.apiVersion < kRequiredApiVersion) {
            missing.push_back(fmt::format("Vulkan 1.3 (has {})",
                                          VersionString(properties.properties.apiVersion)));
            return missing.front();  // the structs below are not filled in for older devices
        }
        if (!FindQueueFamily()) missing.push_back("a queue family with graphics and compute");
        if (!(subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT)) {
            missing.push_back("subgroup operations in compute shaders");
        }
        if ((subgroup.supportedOperations & kRequiredSubgroupOps) != kRequiredSubgroupOps) {
            missing.push_back("subgroup basic/arithmetic/ballot/shuffle operations");
        }
        if (!features13.maintenance4) missing.push_back("the maintenance4 feature");
        if (!features13.synchronization2) missing.push_back("the synchronization2 feature");
        if (!features12.bufferDeviceAddress) missing.push_back("the bufferDeviceAddress feature");
        if (!features.features.shaderInt64) missing.push_back("the shaderInt64 feature");
        for (const char* extension : kRequiredDeviceExtensions) {
            if (!HasExtension(extension)) missing.push_back(extension);
        }
        std::string reason;
        for (const auto& item : missing) reason += (reason.empty() ? "" : ", ") + item;
        return reason.empty() ? reason : "lacks " + reason;
    }
};

}  // namespace

bool EnvironmentSwitchOn(const char* name) { return GetEnv(name) != std::string("0"); }

VulkanContext::VulkanContext() = default;

VulkanContext::~VulkanContext() {
    if (!owns_handles_) return;
    if (device_ != VK_NULL_HANDLE) {
        vkDeviceWaitIdle(device_);
        vkDestroyDevice(device_, nullptr);
    }
    if (messenger_) messenger_->Detach();
    if (instance_ != VK_NULL_HANDLE) vkDestroyInstance(instance_, nullptr);
}

std::unique_ptr<VulkanContext> VulkanContext::CreateHeadless(const VulkanContextOptions& options) {
    bool validation = options.enable_validation;
    if (auto env = GetEnv("OPEN3D_VULKAN_VALIDATION")) validation = (*env != "0");
    std::string device_filter = GetEnv("OPEN3D_VULKAN_DEVICE").value_or(options.device_name_filter);
    // Identical GPUs share a name, so a process per GPU (a Dask worker each,
    // docs/distributed.md) picks its own by position in the enumeration instead.
    std::optional<size_t> device_index;
    if (auto env = GetEnv("OPEN3D_VULKAN_DEVICE_INDEX"); env && !env->empty()) {
        if (env->find_first_not_of("0123456789") != std::string::npos || env->size() > 6) {
            core::ThrowError(
                "OPEN3D_VULKAN_DEVICE_INDEX must be a device number (GPU<N> of `vulkaninfo "
                "--summary`), got '{}'",
                *env);
        }
        device_index = std::stoul(*env);
    }

    uint32_t loader_version = VK_API_VERSION_1_0;
    vkEnumerateInstanceVersion(&loader_version);
    if (loader_version < kRequiredApiVersion) {
        core::ThrowError("Vulkan: the loader supports Vulkan {}, 1.3 is needed; update libvulkan1",
                         VersionString(loader_version));
    }

    std::unique_ptr<VulkanContext> context(new VulkanContext());
    context->owns_handles_ = true;

    std::vector<const char*> layers;
    std::vector<const char*> extensions;
    VkInstanceCreateFlags flags = 0;
    // Lets the loader list portability devices (MoltenVK) as well.
    if (HasInstanceExtension(VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME)) {
        extensions.push_back(VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME);
        flags |= VK_INSTANCE_CREATE_ENUMERATE_PORTABILITY_BIT_KHR;
    }
    VkDebugUtilsMessengerCreateInfoEXT messenger_info{};
    VkValidationFeaturesEXT validation_features =
        MakeInfo<VkValidationFeaturesEXT>(VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT);
    const VkValidationFeatureEnableEXT sync_validation =
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    if (validation) {
        if (!HasInstanceLayer(kValidationLayer)) {
            core::ThrowError(
                "Vulkan validation was requested but {} is not installed. Install it "
                "(Debian: vulkan-validationlayers; elsewhere the Vulkan SDK) or set "
                "OPEN3D_VULKAN_VALIDATION=0",
                kValidationLayer);
        }
        layers.push_back(kValidationLayer);
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        context->messenger_ = std::make_unique<DebugMessenger>();
        messenger_info = context->messenger_->MakeCreateInfo();
        if (options.enable_synchronization_validation) {
            validation_features.enabledValidationFeatureCount = 1;
            validation_features.pEnabledValidationFeatures = &sync_validation;
            messenger_info.pNext = &validation_features;
        }
    }

    VkApplicationInfo app = MakeInfo<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.pApplicationName = "Open3D Gaussian splatting";
    app.pEngineName = "Open3D";
    app.apiVersion = kRequiredApiVersion;
    VkInstanceCreateInfo instance_info =
        MakeInfo<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    instance_info.pNext = validation ? &messenger_info : nullptr;
    instance_info.flags = flags;
    instance_info.pApplicationInfo = &app;
    instance_info.enabledLayerCount = static_cast<uint32_t>(layers.size());
    instance_info.ppEnabledLayerNames = layers.data();
    instance_info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    instance_info.ppEnabledExtensionNames = extensions.data();
    VkResult result = vkCreateInstance(&instance_info, nullptr, &context->instance_);
    if (result == VK_ERROR_INCOMPATIBLE_DRIVER) {
        core::ThrowError("Vulkan: no driver (ICD) was found. {}", kInstallHint);
    }
    CheckVk(result, "vkCreateInstance");
    if (context->messenger_) context->messenger_->Attach(context->instance_);

    uint32_t count = 0;
    vkEnumeratePhysicalDevices(context->instance_, &count, nullptr);
    std::vector<VkPhysicalDevice> devices(count);
    vkEnumeratePhysicalDevices(context->instance_, &count, devices.data());
    if (devices.empty()) core::ThrowError("Vulkan: no physical device was found. {}", kInstallHint);

    VkPhysicalDevice best = VK_NULL_HANDLE;
    int best_rank = -1;
    std::string rejected;
    for (size_t i = 0; i < devices.size(); ++i) {
        VkPhysicalDevice device = devices[i];
        DeviceQuery query(device);
        std::string name = query.properties.properties.deviceName;
        std::string why = query.WhyUnsuitable();
        if (why.empty() && device_index && i != *device_index) {
            why = fmt::format("is device {}, not OPEN3D_VULKAN_DEVICE_INDEX={}", i, *device_index);
        }
        if (why.empty() && !device_filter.empty() &&
            name.find(device_filter) == std::string::npos) {
            why = fmt::format("does not match the device filter '{}'", device_filter);
        }
        if (!why.empty()) {
            rejected += fmt::format("\n  {}: {}", name, why);
            continue;
        }
        int rank = DeviceTypeRank(query.properties.properties.deviceType);
        if (rank > best_rank) {
            best = device;
            best_rank = rank;
        }
    }
    if (best == VK_NULL_HANDLE) {
        core::ThrowError("Vulkan: no usable device.{}\n{}", rejected, kInstallHint);
    }
    const DeviceQuery chosen(best);
    OptionalExtensions optional;
    optional.external_memory_fd = chosen.HasExtension(VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
    optional.external_semaphore_fd =
        optional.external_memory_fd &&
        chosen.HasExtension(VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME);
    optional.host_memory_import = EnvironmentSwitchOn("OPEN3D_VULKAN_HOST_IMPORT") &&
                                  chosen.HasExtension(VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME);
    context->InitDevice(best, *chosen.FindQueueFamily(), optional,
                        EnvironmentSwitchOn("OPEN3D_VULKAN_TRANSFER_QUEUE")
                            ? chosen.FindTransferFamily()
                            : std::nullopt);
    context->LimitWorkgroupsX(options.max_workgroups_x);
    return context;
}

std::unique_ptr<VulkanContext> VulkanContext::CreateFromBorrowed(
    const BorrowedVulkanHandles& handles) {
    if (handles.instance == VK_NULL_HANDLE || handles.physical_device == VK_NULL_HANDLE ||
        handles.device == VK_NULL_HANDLE || handles.queue == VK_NULL_HANDLE) {
        core::ThrowError(
            "Vulkan: borrowed handles must all be set (instance, physical device, "
            "device, queue)");
    }
    DeviceQuery query(handles.physical_device);
    std::string why = query.WhyUnsuitable();
    if (!why.empty()) {
        core::ThrowError("Vulkan: the host application's device {} {}",
                         query.properties.properties.deviceName, why);
    }
    if (handles.queue_family_index >= query.queue_families.size() ||
        (query.queue_families[handles.queue_family_index].queueFlags & VK_QUEUE_COMPUTE_BIT) == 0) {
        core::ThrowError("Vulkan: borrowed queue family {} has no compute support",
                         handles.queue_family_index);
    }
    std::unique_ptr<VulkanContext> context(new VulkanContext());
    context->owns_handles_ = false;
    context->instance_ = handles.instance;
    context->physical_device_ = handles.physical_device;
    context->device_ = handles.device;
    context->queue_ = handles.queue;
    if (handles.transfer_queue != VK_NULL_HANDLE) {
        if (handles.transfer_queue_family_index >= query.queue_families.size()) {
            core::ThrowError("Vulkan: borrowed transfer queue family {} does not exist",
                             handles.transfer_queue_family_index);
        }
        context->transfer_queue_ = handles.transfer_queue;
        context->transfer_family_ = handles.transfer_queue_family_index;
    }
    OptionalExtensions optional;
    optional.external_memory_fd = handles.external_memory_fd_enabled;
    optional.external_semaphore_fd = handles.external_semaphore_fd_enabled;
    optional.host_memory_import = handles.host_memory_import_enabled;
    context->InitDevice(handles.physical_device, handles.queue_family_index, optional);
    context->LimitWorkgroupsX(handles.max_workgroups_x);
    return context;
}

void VulkanContext::LimitWorkgroupsX(uint32_t max_workgroups_x) {
    if (max_workgroups_x == 0) return;
    info_.max_compute_workgroups_x = std::min(info_.max_compute_workgroups_x, max_workgroups_x);
}

void VulkanContext::InitDevice(VkPhysicalDevice physical_device, uint32_t queue_family_index,
                               const OptionalExtensions& optional,
                               std::optional<uint32_t> transfer_family) {
    physical_device_ = physical_device;
    DeviceQuery query(physical_device);
    if (owns_handles_) {
        // Memory export (zero-copy sharing with GL) is optional: enabled when present.
        std::vector<const char*> extensions(std::begin(kRequiredDeviceExtensions),
                                            std::end(kRequiredDeviceExtensions));
        if (optional.external_memory_fd) {
            extensions.push_back(VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME);
        }
        if (optional.external_semaphore_fd) {
            extensions.push_back(VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME);
        }
        if (optional.host_memory_import) {
            extensions.push_back(VK_EXT_EXTERNAL_MEMORY_HOST_EXTENSION_NAME);
        }
        const float priority = 1.0f;
        std::vector<VkDeviceQueueCreateInfo> queue_infos(1);
        queue_infos[0] =
            MakeInfo<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
        queue_infos[0].queueFamilyIndex = queue_family_index;
        queue_infos[0].queueCount = 1;
        queue_infos[0].pQueuePriorities = &priority;
        if (transfer_family && *transfer_family != queue_family_index) {
            queue_infos.push_back(queue_infos[0]);
            queue_infos[1].queueFamilyIndex = *transfer_family;
        }
        // maintenance4: glslang's vulkan1.3 SPIR-V declares workgroup sizes with
        // LocalSizeId, which the validation layer rejects without it.
        VkPhysicalDeviceVulkan13Features features13 = MakeInfo<VkPhysicalDeviceVulkan13Features>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES);
        features13.maintenance4 = VK_TRUE;
        features13.synchronization2 = VK_TRUE;
        // bufferDeviceAddress and shaderInt64: the shape and SH words and the projected
        // records are read through 64-bit device addresses, as they can outgrow the range
        // one storage binding reaches (docs/vulkan.md "Buffers").
        VkPhysicalDeviceVulkan12Features features12 = MakeInfo<VkPhysicalDeviceVulkan12Features>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES);
        features12.bufferDeviceAddress = VK_TRUE;
        features12.pNext = &features13;
        VkPhysicalDeviceFeatures2 features =
            MakeInfo<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
        features.features.shaderInt64 = VK_TRUE;
        features.pNext = &features12;
        VkDeviceCreateInfo device_info =
            MakeInfo<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
        device_info.pNext = &features;
        device_info.queueCreateInfoCount = static_cast<uint32_t>(queue_infos.size());
        device_info.pQueueCreateInfos = queue_infos.data();
        device_info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
        device_info.ppEnabledExtensionNames = extensions.data();
        CheckVk(vkCreateDevice(physical_device, &device_info, nullptr, &device_), "vkCreateDevice");
        vkGetDeviceQueue(device_, queue_family_index, 0, &queue_);
        if (queue_infos.size() > 1) {
            transfer_family_ = *transfer_family;
            vkGetDeviceQueue(device_, transfer_family_, 0, &transfer_queue_);
        }
    }
    vkGetPhysicalDeviceMemoryProperties(physical_device, &memory_properties_);
    // Where the device reports a budget (VK_EXT_memory_budget: NVIDIA, AMD; a physical-device
    // query, usable when the extension is supported), a heap's room is at most that budget
    // less what the process already uses: the heap size counts memory the driver, other
    // processes and this process's other contexts hold, and each context kept its own
    // count, so two contexts of one process (gs-bench's exact and level-of-detail backends)
    // each saw the whole heap and the driver failed with VK_ERROR_OUT_OF_DEVICE_MEMORY.
    std::array<VkDeviceSize, VK_MAX_MEMORY_HEAPS> heap_budgets{};
    bool have_budgets = false;
    if (query.HasExtension(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME)) {
        VkPhysicalDeviceMemoryBudgetPropertiesEXT budget_properties =
            MakeInfo<VkPhysicalDeviceMemoryBudgetPropertiesEXT>(
                VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT);
        VkPhysicalDeviceMemoryProperties2 properties2 = MakeInfo<VkPhysicalDeviceMemoryProperties2>(
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2);
        properties2.pNext = &budget_properties;
        vkGetPhysicalDeviceMemoryProperties2(physical_device, &properties2);
        // heapBudget is what the whole process may use; what it already uses (another
        // context, GL) is not this context's to take.
        for (uint32_t h = 0; h < memory_properties_.memoryHeapCount; ++h) {
            const VkDeviceSize budget = budget_properties.heapBudget[h];
            const VkDeviceSize usage = budget_properties.heapUsage[h];
            heap_budgets[h] = budget > usage ? budget - usage : 0;
        }
        have_budgets = true;
    }
    memory_budget_.Init(memory_properties_, have_budgets ? &heap_budgets : nullptr);

    const VkPhysicalDeviceProperties& properties = query.properties.properties;
    info_.name = properties.deviceName;
    info_.type = DeviceTypeName(properties.deviceType);
    info_.driver_name = query.driver.driverName;
    info_.driver_info = query.driver.driverInfo;
    info_.api_version = properties.apiVersion;
    info_.vendor_id = properties.vendorID;
    info_.subgroup_size = query.subgroup.subgroupSize;
    info_.min_subgroup_size = query.size_control.minSubgroupSize;
    info_.max_subgroup_size = query.size_control.maxSubgroupSize;
    info_.max_compute_shared_memory = properties.limits.maxComputeSharedMemorySize;
    info_.min_storage_buffer_offset_alignment = properties.limits.minStorageBufferOffsetAlignment;
    info_.max_storage_buffer_range = properties.limits.maxStorageBufferRange;
    info_.max_compute_workgroups_x = properties.limits.maxComputeWorkGroupCount[0];
    const auto& family = query.queue_families[queue_family_index];
    info_.timestamp_period_ns =
        family.timestampValidBits > 0 ? properties.limits.timestampPeriod : 0.0f;
    info_.queue_family_index = queue_family_index;
    std::copy(std::begin(query.ids.deviceUUID), std::end(query.ids.deviceUUID),
              info_.device_uuid.begin());
    std::copy(std::begin(query.ids.driverUUID), std::end(query.ids.driverUUID),
              info_.driver_uuid.begin());

    if (optional.host_memory_import) {
        VkPhysicalDeviceExternalMemoryHostPropertiesEXT host_import =
            MakeInfo<VkPhysicalDeviceExternalMemoryHostPropertiesEXT>(
                VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_MEMORY_HOST_PROPERTIES_EXT);
        VkPhysicalDeviceProperties2 host_properties =
            MakeInfo<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
        host_properties.pNext = &host_import;
        vkGetPhysicalDeviceProperties2(physical_device, &host_properties);
        host_import_alignment_ = host_import.minImportedHostPointerAlignment;
    }
    LoadDeviceFunctions(optional);
    ReportDevice();
}

void VulkanContext::LoadDeviceFunctions(const OptionalExtensions& optional) {
    if (optional.host_memory_import) {
        get_host_pointer_properties_ = reinterpret_cast<PFN_vkGetMemoryHostPointerPropertiesEXT>(
            vkGetDeviceProcAddr(device_, "vkGetMemoryHostPointerPropertiesEXT"));
    }
    push_descriptor_set_ = reinterpret_cast<PFN_vkCmdPushDescriptorSetKHR>(
        vkGetDeviceProcAddr(device_, "vkCmdPushDescriptorSetKHR"));
    if (push_descriptor_set_ == nullptr) {
        core::ThrowError(
            "Vulkan: vkCmdPushDescriptorSetKHR is unavailable; the device must be "
            "created with {}",
            VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
    }
    if (optional.external_semaphore_fd) {
        LoadExtensionFunction(device_, "vkGetSemaphoreFdKHR",
                              VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME, get_semaphore_fd_);
    }
    if (optional.external_memory_fd) {
        LoadExtensionFunction(device_, "vkGetMemoryFdKHR", VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME,
                              get_memory_fd_);
    }
}

void VulkanContext::ReportDevice() const {
    core::LogInfo(
        "Vulkan device: {} ({}), driver {} [{}], Vulkan {}, subgroup size {} (range {}..{}), "
        "{} KiB shared memory, queue family {}{}, memory export {}, semaphore export {}, host "
        "import {}, validation "
        "{}{}",
        info_.name, info_.type, info_.driver_name, info_.driver_info,
        VersionString(info_.api_version), info_.subgroup_size, info_.min_subgroup_size,
        info_.max_subgroup_size, info_.max_compute_shared_memory / 1024, info_.queue_family_index,
        HasTransferQueue() ? fmt::format(" (+ transfer family {})", transfer_family_) : "",
        SupportsExternalMemoryFd() ? "on" : "off", SupportsExternalSemaphoreFd() ? "on" : "off",
        CanImportHostMemory() ? "on" : "off", IsValidationEnabled() ? "on" : "off",
        owns_handles_ ? "" : ", handles borrowed from the host application");
}

ValidationMessageCounts VulkanContext::GetValidationMessageCounts() const {
    return messenger_ ? messenger_->GetCounts() : ValidationMessageCounts{};
}

uint32_t VulkanContext::FindMemoryType(uint32_t type_bits, VkMemoryPropertyFlags required,
                                       VkMemoryPropertyFlags preferred) const {
    std::optional<uint32_t> fallback;
    for (uint32_t i = 0; i < memory_properties_.memoryTypeCount; ++i) {
        if (!(type_bits & (1u << i))) continue;
        VkMemoryPropertyFlags flags = memory_properties_.memoryTypes[i].propertyFlags;
        if ((flags & required) != required) continue;
        if ((flags & preferred) == preferred) return i;
        if (!fallback) fallback = i;
    }
    if (!fallback) {
        core::ThrowError(
            "Vulkan: device {} has no memory type with properties {:#x} (allowed "
            "types {:#x})",
            info_.name, required, type_bits);
    }
    return *fallback;
}

void VulkanContext::WaitIdle() const { CheckVk(vkDeviceWaitIdle(device_), "vkDeviceWaitIdle"); }

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
