// An empty Vulkan instance held so that the loader keeps the drivers loaded; why, in
// docs/environment-notes.md "NVIDIA GPUs".
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanDriversLoaded.h"

#include <vulkan/vulkan.h>

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

std::shared_ptr<void> KeepVulkanDriversLoaded() {
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "open3d-keep-vulkan-drivers-loaded";
    app.apiVersion = VK_API_VERSION_1_0;
    VkInstanceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    info.pApplicationInfo = &app;
    VkInstance instance = VK_NULL_HANDLE;
    if (vkCreateInstance(&info, nullptr, &instance) != VK_SUCCESS) return nullptr;
    return std::shared_ptr<void>(
        instance, [](void* i) { vkDestroyInstance(static_cast<VkInstance>(i), nullptr); });
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
