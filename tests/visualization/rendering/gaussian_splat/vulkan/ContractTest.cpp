// The contract header compiles as C++ (its static_asserts hold) and the GLSL side lays
// the mirrored structs out at the offsets the C++ side asserts.
#include <gtest/gtest.h>

#include <cstring>

#include "VulkanTestFixture.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/ComputePipeline.h"
#include "shaders/GaussianSplatContract.h"
#include "vulkan_test_shaders/TestShaders.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering::vulkan;
namespace shader = visualization::rendering::shader;

TEST(GaussianSplatContract, CompilesAsCpp) {
    // Reaching this line means every static_assert in the header held.
    EXPECT_EQ(shader::kRadixSortBlockSize,
              shader::kRadixSortWorkgroupSize * shader::kRadixSortItemsPerInvocation);
    EXPECT_EQ(sizeof(shader::RadixSortParams), 32u);
    EXPECT_EQ(sizeof(shader::RadixSortPushConstants), 32u);
}

using GaussianSplatContractGpu = VulkanTest;

TEST_F(GaussianSplatContractGpu, ShaderLayoutMatchesCpp) {
    UniqueDescriptorSetLayout set_layout = CreateStorageBufferPushLayout(Context(), 2);
    UniquePipelineLayout layout =
        CreatePipelineLayout(Context(), set_layout.Get(), sizeof(shader::RadixSortPushConstants));
    UniquePipeline pipeline =
        CreateComputePipeline(Context(), layout.Get(), spirv::kContractProbe, "probe");
    Buffer params(Context(), sizeof(shader::RadixSortParams), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                  MemoryUsage::kHostReadback);
    Buffer push_out(Context(), sizeof(shader::RadixSortPushConstants),
                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::kHostReadback);
    shader::RadixSortPushConstants push{};
    push.shift = 201;
    push.digit_bits = 202;
    push.count_index = 203;
    push.max_count = 204;
    push.target_blocks = 205;
    SubmitAndWait(Context(), Pool(), [&](VkCommandBuffer cmd) {
        VkDescriptorBufferInfo infos[2] = {{params.Get(), 0, VK_WHOLE_SIZE},
                                           {push_out.Get(), 0, VK_WHOLE_SIZE}};
        VkWriteDescriptorSet writes[2] = {};
        for (uint32_t i = 0; i < 2; ++i) {
            writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
            writes[i].dstBinding = i;
            writes[i].descriptorCount = 1;
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[i].pBufferInfo = &infos[i];
        }
        Context().GetCmdPushDescriptorSet()(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout.Get(), 0, 2,
                                            writes);
        vkCmdPushConstants(cmd, layout.Get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.Get());
        vkCmdDispatch(cmd, 1, 1, 1);
        RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                            VK_ACCESS_2_HOST_READ_BIT);
    });
    shader::RadixSortParams p;
    std::memcpy(&p, params.GetMapped(), sizeof(p));
    EXPECT_EQ(p.dispatch_x, 101u);
    EXPECT_EQ(p.dispatch_y, 102u);
    EXPECT_EQ(p.dispatch_z, 103u);
    EXPECT_EQ(p.count, 104u);
    EXPECT_EQ(p.num_blocks, 105u);
    EXPECT_EQ(p.flags, 106u);
    EXPECT_EQ(p.block_size, 107u);
    EXPECT_EQ(p.reserved1, 108u);
    shader::RadixSortPushConstants q;
    std::memcpy(&q, push_out.GetMapped(), sizeof(q));
    EXPECT_EQ(q.shift, 201u);
    EXPECT_EQ(q.digit_bits, 202u);
    EXPECT_EQ(q.count_index, 203u);
    EXPECT_EQ(q.max_count, 204u);
    EXPECT_EQ(q.target_blocks, 205u);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
