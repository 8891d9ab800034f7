#include "open3d/visualization/rendering/gaussian_splat/vulkan/DebugMessenger.h"

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

VkDebugUtilsMessengerCreateInfoEXT DebugMessenger::MakeCreateInfo() {
    VkDebugUtilsMessengerCreateInfoEXT info{};
    info.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    // Info and verbose are requested too but only counted, not treated as problems: the
    // loader sends several of those on every run.
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = &DebugMessenger::Callback;
    info.pUserData = this;
    return info;
}

void DebugMessenger::Attach(VkInstance instance) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create == nullptr) {
        core::ThrowError(
            "Vulkan: vkCreateDebugUtilsMessengerEXT is missing although "
            "VK_EXT_debug_utils was enabled");
    }
    VkDebugUtilsMessengerCreateInfoEXT info = MakeCreateInfo();
    CheckVk(create(instance, &info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
    instance_ = instance;
}

void DebugMessenger::Detach() {
    if (messenger_ == VK_NULL_HANDLE) return;
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy != nullptr) destroy(instance_, messenger_, nullptr);
    messenger_ = VK_NULL_HANDLE;
    instance_ = VK_NULL_HANDLE;
}

ValidationMessageCounts DebugMessenger::GetCounts() const {
    ValidationMessageCounts counts;
    counts.errors = errors_.load();
    counts.warnings = warnings_.load();
    counts.infos = infos_.load();
    return counts;
}

VkBool32 VKAPI_CALL DebugMessenger::Callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                             void* user_data) {
    auto* self = static_cast<DebugMessenger*>(user_data);
    const char* id = data->pMessageIdName != nullptr ? data->pMessageIdName : "";
    const char* text = data->pMessage != nullptr ? data->pMessage : "";
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        ++self->errors_;
        core::LogError("Vulkan validation error [{}]: {}", id, text);
    } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        ++self->warnings_;
        core::LogWarning("Vulkan validation warning [{}]: {}", id, text);
    } else {
        ++self->infos_;
        core::LogDebug("Vulkan validation info [{}]: {}", id, text);
    }
    return VK_FALSE;  // never abort the call that triggered the message
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
