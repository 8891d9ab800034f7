// The context: creation, device report, subgroup size, borrowed handles, a dispatch, and
// that validation messages are counted (so the fixture's zero-message check means something).
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "VulkanTestFixture.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/ComputePipeline.h"
#include "vulkan_test_shaders/TestShaders.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering::vulkan;

bool IsPowerOfTwo(uint32_t x) { return x != 0 && (x & (x - 1)) == 0; }

// Runs trivial_dispatch.comp for n values on `context`; returns n values and the subgroup
// size the shader saw.
std::vector<uint32_t> RunTrivialDispatch(const VulkanContext& context, uint32_t n) {
    CommandPool pool(context);
    UniqueDescriptorSetLayout set_layout = CreateStorageBufferPushLayout(context, 1);
    UniquePipelineLayout layout = CreatePipelineLayout(context, set_layout.Get(), 4);
    UniquePipeline pipeline =
        CreateComputePipeline(context, layout.Get(), spirv::kTrivialDispatch, "trivial");
    Buffer out(context, (n + 1) * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
               MemoryUsage::kHostReadback);
    SubmitAndWait(context, pool, [&](VkCommandBuffer cmd) {
        VkDescriptorBufferInfo info{out.Get(), 0, VK_WHOLE_SIZE};
        VkWriteDescriptorSet write =
            MakeInfo<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
        write.dstBinding = 0;
        write.descriptorCount = 1;
        write.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        write.pBufferInfo = &info;
        context.GetCmdPushDescriptorSet()(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout.Get(), 0, 1,
                                          &write);
        vkCmdPushConstants(cmd, layout.Get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, 4, &n);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.Get());
        vkCmdDispatch(cmd, (n + 63) / 64, 1, 1);
        RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                            VK_ACCESS_2_HOST_READ_BIT);
    });
    const auto* mapped = static_cast<const uint32_t*>(out.GetMapped());
    return std::vector<uint32_t>(mapped, mapped + n + 1);
}

using VulkanContextTest = VulkanTest;

TEST_F(VulkanContextTest, DescribesDevice) {
    const VulkanDeviceInfo& info = Context().GetDeviceInfo();
    EXPECT_TRUE(Context().OwnsHandles());
    EXPECT_NE(Context().GetDevice(), VK_NULL_HANDLE);
    EXPECT_NE(Context().GetQueue(), VK_NULL_HANDLE);
    EXPECT_FALSE(info.name.empty());
    EXPECT_FALSE(info.driver_name.empty());
    EXPECT_GE(info.api_version, VK_API_VERSION_1_3);
    EXPECT_TRUE(IsPowerOfTwo(info.subgroup_size)) << info.subgroup_size;
    EXPECT_LE(info.min_subgroup_size, info.subgroup_size);
    EXPECT_GE(info.max_subgroup_size, info.subgroup_size);
    EXPECT_GE(info.max_compute_shared_memory, 16384u);
    EXPECT_TRUE(IsPowerOfTwo(uint32_t(info.min_storage_buffer_offset_alignment)));
    // LP_NATIVE_VECTOR_WIDTH=128/512 makes lavapipe use subgroups of 4/16
    // (docs/environment-notes.md).
    if (info.driver_name == "llvmpipe" && std::getenv("LP_NATIVE_VECTOR_WIDTH") == nullptr) {
        EXPECT_EQ(info.subgroup_size, 8u) << "lavapipe's fixed subgroup size";
    }
}

TEST_F(VulkanContextTest, ReportsDeviceInLog) {
    std::vector<std::string> messages;
    core::LogSink previous = core::SetLogSink(
        [&](core::LogLevel, std::string_view message) { messages.emplace_back(message); });
    std::string skip, failure;
    auto context = CreateTestContext(skip, failure);
    core::SetLogSink(previous);
    ASSERT_TRUE(context) << skip << failure;
    const VulkanDeviceInfo& info = context->GetDeviceInfo();
    bool reported = false;
    for (const auto& message : messages) {
        reported |= message.find("Vulkan device: " + info.name) != std::string::npos &&
                    message.find("subgroup size " + std::to_string(info.subgroup_size)) !=
                        std::string::npos &&
                    message.find(info.driver_name) != std::string::npos;
    }
    EXPECT_TRUE(reported) << "no log line names the device, driver and subgroup size";
    EXPECT_EQ(context->GetValidationMessageCounts().Problems(), 0u);
}

TEST_F(VulkanContextTest, TrivialDispatch) {
    for (uint32_t n : {1u, 63u, 64u, 1000u}) {
        std::vector<uint32_t> values = RunTrivialDispatch(Context(), n);
        for (uint32_t i = 0; i < n; ++i) ASSERT_EQ(values[i], 3 * i + 1) << "n " << n;
        const VulkanDeviceInfo& info = Context().GetDeviceInfo();
        EXPECT_GE(values[n], info.min_subgroup_size);
        EXPECT_LE(values[n], info.max_subgroup_size);
    }
}

TEST_F(VulkanContextTest, BorrowedHandlesAreNotDestroyed) {
    BorrowedVulkanHandles handles;
    handles.instance = Context().GetInstance();
    handles.physical_device = Context().GetPhysicalDevice();
    handles.device = Context().GetDevice();
    handles.queue_family_index = Context().GetQueueFamilyIndex();
    handles.queue = Context().GetQueue();
    {
        auto borrowed = VulkanContext::CreateFromBorrowed(handles);
        EXPECT_FALSE(borrowed->OwnsHandles());
        EXPECT_FALSE(borrowed->IsValidationEnabled());  // the host owns the messenger
        EXPECT_EQ(borrowed->GetDeviceInfo().name, Context().GetDeviceInfo().name);
        EXPECT_EQ(RunTrivialDispatch(*borrowed, 10)[9], 28u);
    }
    // The owner's device still works after the borrower is gone.
    EXPECT_EQ(RunTrivialDispatch(Context(), 10)[9], 28u);
}

TEST_F(VulkanContextTest, BorrowedHandlesMustBeSet) {
    EXPECT_THROW(VulkanContext::CreateFromBorrowed({}), core::Open3DError);
}

TEST_F(VulkanContextTest, NoMatchingDeviceThrowsActionableError) {
    if (std::getenv("OPEN3D_VULKAN_DEVICE") != nullptr)
        GTEST_SKIP() << "OPEN3D_VULKAN_DEVICE is set";
    VulkanContextOptions options;
    options.device_name_filter = "no-such-device-name";
    try {
        VulkanContext::CreateHeadless(options);
        FAIL() << "expected core::Open3DError";
    } catch (const core::Open3DError& error) {
        std::string message = error.what();
        EXPECT_NE(message.find("no usable device"), std::string::npos) << message;
        EXPECT_NE(message.find("vulkaninfo"), std::string::npos) << message;
    }
}

TEST_F(VulkanContextTest, CountsValidationMessages) {
    if (!Context().IsValidationEnabled()) GTEST_SKIP() << "validation is off";
    std::string skip, failure;
    auto context = CreateTestContext(skip, failure);
    ASSERT_TRUE(context);
    // A deliberate mistake that drivers tolerate: a buffer without any usage bit (the
    // expected error is kept out of the log).
    core::LogSink previous = core::SetLogSink([](core::LogLevel, std::string_view) {});
    VkBufferCreateInfo info = MakeInfo<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
    info.size = 64;
    info.usage = 0;
    VkBuffer buffer = VK_NULL_HANDLE;
    VkResult result = vkCreateBuffer(context->GetDevice(), &info, nullptr, &buffer);
    if (result == VK_SUCCESS) vkDestroyBuffer(context->GetDevice(), buffer, nullptr);
    core::SetLogSink(previous);
    EXPECT_GE(context->GetValidationMessageCounts().errors, 1u);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
