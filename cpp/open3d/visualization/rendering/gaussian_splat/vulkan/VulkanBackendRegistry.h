// The Vulkan backend as code outside the Vulkan layer sees it (no Vulkan types, so the
// Filament layer and its tests can include this; docs/DESIGN.md "Layers").
#pragma once

#include <cstdint>

#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

/// Registers the factory "vulkan" (a headless context per backend; validation follows
/// OPEN3D_VULKAN_VALIDATION). Creating the backend throws core::Open3DError when no usable
/// Vulkan device exists. Safe to call more than once.
void RegisterVulkanBackend();

/// Validation-layer errors and warnings reported on `backend`'s context so far; 0 for a
/// backend that is not the Vulkan backend or runs without validation.
uint64_t GetValidationProblemCount(const GaussianSplatBackend& backend);

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
