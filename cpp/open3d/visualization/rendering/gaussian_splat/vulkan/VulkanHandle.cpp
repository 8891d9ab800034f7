#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

#include "open3d/core/Exception.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

const char* VkResultName(VkResult result) {
    switch (result) {
#define OPEN3D_VK_RESULT_CASE(name) \
    case name:                      \
        return #name;
        OPEN3D_VK_RESULT_CASE(VK_SUCCESS)
        OPEN3D_VK_RESULT_CASE(VK_NOT_READY)
        OPEN3D_VK_RESULT_CASE(VK_TIMEOUT)
        OPEN3D_VK_RESULT_CASE(VK_INCOMPLETE)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_INITIALIZATION_FAILED)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_DEVICE_LOST)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_MEMORY_MAP_FAILED)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_LAYER_NOT_PRESENT)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_TOO_MANY_OBJECTS)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
        OPEN3D_VK_RESULT_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
#undef OPEN3D_VK_RESULT_CASE
        default:
            return "VkResult(unknown)";
    }
}

void CheckVk(VkResult result, const char* what) {
    if (result == VK_SUCCESS) return;
    if (result == VK_ERROR_DEVICE_LOST) {
        core::ThrowError(
            "Vulkan: {} failed with VK_ERROR_DEVICE_LOST (a shader crashed or ran "
            "too long; run with OPEN3D_VULKAN_VALIDATION=1 to find out more)",
            what);
    }
    core::ThrowError("Vulkan: {} failed with {} ({})", what, VkResultName(result),
                     static_cast<int>(result));
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
