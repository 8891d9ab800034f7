#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanBackendRegistry.h"

#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

void RegisterVulkanBackend() {
    RegisterGaussianSplatBackend("vulkan", [] {
        return std::make_unique<GaussianSplatVulkanBackend>(VulkanContext::CreateHeadless());
    });
}

uint64_t GetValidationProblemCount(const GaussianSplatBackend& backend) {
    const auto* vulkan = dynamic_cast<const GaussianSplatVulkanBackend*>(&backend);
    return vulkan ? vulkan->GetContext().GetValidationMessageCounts().Problems() : 0;
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
