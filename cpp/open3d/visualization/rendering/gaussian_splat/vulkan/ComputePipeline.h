// Creation of the layouts and compute pipelines the recorders own. Descriptors are pushed
// (VK_KHR_push_descriptor) when recording, so a recorder needs no descriptor pool and can
// bind any caller's buffers without allocating.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <span>

#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class VulkanContext;

/// A push-descriptor set layout of `num_bindings` storage buffers (bindings 0..n-1) for
/// the compute stage.
UniqueDescriptorSetLayout CreateStorageBufferPushLayout(const VulkanContext& context,
                                                        uint32_t num_bindings);

/// One descriptor set layout and a compute push-constant range of `push_constant_bytes`.
UniquePipelineLayout CreatePipelineLayout(const VulkanContext& context,
                                          VkDescriptorSetLayout set_layout,
                                          uint32_t push_constant_bytes);

/// A compute pipeline from embedded SPIR-V (entry point "main"). `name` appears in errors.
UniquePipeline CreateComputePipeline(const VulkanContext& context, VkPipelineLayout layout,
                                     std::span<const uint32_t> spirv, const char* name,
                                     const VkSpecializationInfo* specialization = nullptr);

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
