// Keeping the Vulkan drivers loaded, for the OpenGL-on-EGL layer (no Vulkan types, no Eigen:
// the Filament layer includes it beside X11 headers).
#pragma once

#include <memory>

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

/// Keeps the process's Vulkan drivers loaded while the returned handle lives: a Vulkan
/// instance with nothing enabled (the loader unloads a driver only when no instance is
/// left). NVIDIA's Vulkan driver, unloaded, ends the EGL display of its GPU that OpenGL on
/// EGL renders with (docs/environment-notes.md "NVIDIA GPUs"); the EGL engine holds one.
/// Null, and nothing is kept, where no Vulkan loader or driver answers.
std::shared_ptr<void> KeepVulkanDriversLoaded();

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
