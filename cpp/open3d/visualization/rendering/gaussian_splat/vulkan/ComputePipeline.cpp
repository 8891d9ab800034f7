#include "open3d/visualization/rendering/gaussian_splat/vulkan/ComputePipeline.h"

#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

UniqueDescriptorSetLayout CreateStorageBufferPushLayout(const VulkanContext& context,
                                                        uint32_t num_bindings) {
    std::vector<VkDescriptorSetLayoutBinding> bindings(num_bindings);
    for (uint32_t i = 0; i < num_bindings; ++i) {
        bindings[i].binding = i;
        bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        bindings[i].descriptorCount = 1;
        bindings[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo info = MakeInfo<VkDescriptorSetLayoutCreateInfo>(
        VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
    info.flags = VK_DESCRIPTOR_SET_LAYOUT_CREATE_PUSH_DESCRIPTOR_BIT_KHR;
    info.bindingCount = num_bindings;
    info.pBindings = bindings.data();
    VkDescriptorSetLayout layout = VK_NULL_HANDLE;
    CheckVk(vkCreateDescriptorSetLayout(context.GetDevice(), &info, nullptr, &layout),
            "vkCreateDescriptorSetLayout");
    return UniqueDescriptorSetLayout(context.GetDevice(), layout);
}

UniquePipelineLayout CreatePipelineLayout(const VulkanContext& context,
                                          VkDescriptorSetLayout set_layout,
                                          uint32_t push_constant_bytes) {
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_constant_bytes};
    VkPipelineLayoutCreateInfo info =
        MakeInfo<VkPipelineLayoutCreateInfo>(VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO);
    info.setLayoutCount = 1;
    info.pSetLayouts = &set_layout;
    info.pushConstantRangeCount = push_constant_bytes > 0 ? 1 : 0;
    info.pPushConstantRanges = &range;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    CheckVk(vkCreatePipelineLayout(context.GetDevice(), &info, nullptr, &layout),
            "vkCreatePipelineLayout");
    return UniquePipelineLayout(context.GetDevice(), layout);
}

UniquePipeline CreateComputePipeline(const VulkanContext& context, VkPipelineLayout layout,
                                     std::span<const uint32_t> spirv, const char* name,
                                     const VkSpecializationInfo* specialization) {
    VkDevice device = context.GetDevice();
    VkShaderModuleCreateInfo module_info =
        MakeInfo<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
    module_info.codeSize = spirv.size_bytes();
    module_info.pCode = spirv.data();
    VkShaderModule module = VK_NULL_HANDLE;
    VkResult result = vkCreateShaderModule(device, &module_info, nullptr, &module);
    if (result != VK_SUCCESS) {
        core::ThrowError("Vulkan: creating the shader module of {} failed with {}", name,
                         VkResultName(result));
    }
    UniqueShaderModule owned_module(device, module);  // only needed until the pipeline exists

    VkComputePipelineCreateInfo info =
        MakeInfo<VkComputePipelineCreateInfo>(VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO);
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module;
    info.stage.pName = "main";
    info.stage.pSpecializationInfo = specialization;
    info.layout = layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    result = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &pipeline);
    if (result != VK_SUCCESS) {
        core::ThrowError("Vulkan: creating the compute pipeline {} failed with {}", name,
                         VkResultName(result));
    }
    return UniquePipeline(device, pipeline);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
