// Receives the validation layer's messages, logs each through core logging and counts
// them by severity so tests can fail on any message.
#pragma once

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>

#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class DebugMessenger {
public:
    DebugMessenger() = default;
    ~DebugMessenger() { Detach(); }
    DebugMessenger(const DebugMessenger&) = delete;
    DebugMessenger& operator=(const DebugMessenger&) = delete;

    /// For VkInstanceCreateInfo::pNext, so that vkCreateInstance and vkDestroyInstance are
    /// reported too. `this` must outlive the instance.
    VkDebugUtilsMessengerCreateInfoEXT MakeCreateInfo();
    /// Creates the messenger of a live instance.
    void Attach(VkInstance instance);
    /// Destroys it; must run before vkDestroyInstance.
    void Detach();

    ValidationMessageCounts GetCounts() const;

private:
    static VkBool32 VKAPI_CALL Callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                        VkDebugUtilsMessageTypeFlagsEXT types,
                                        const VkDebugUtilsMessengerCallbackDataEXT* data,
                                        void* user_data);

    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    std::atomic<uint64_t> errors_{0};
    std::atomic<uint64_t> warnings_{0};
    std::atomic<uint64_t> infos_{0};
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
