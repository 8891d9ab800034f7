#include "open3d/visualization/rendering/gaussian_splat/vulkan/GpuTimestamps.h"

#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

GpuTimestamps::GpuTimestamps(const VulkanContext& context, uint32_t num_passes)
    : device_(context.GetDevice()), num_passes_(num_passes) {
    uint32_t num_families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(context.GetPhysicalDevice(), &num_families, nullptr);
    std::vector<VkQueueFamilyProperties> families(num_families);
    vkGetPhysicalDeviceQueueFamilyProperties(context.GetPhysicalDevice(), &num_families,
                                             families.data());
    const uint32_t valid_bits = families.at(context.GetQueueFamilyIndex()).timestampValidBits;
    period_ns_ = context.GetDeviceInfo().timestamp_period_ns;
    if (valid_bits == 0 || period_ns_ <= 0.0 || num_passes == 0) return;
    valid_mask_ = valid_bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << valid_bits) - 1;

    VkQueryPoolCreateInfo info =
        MakeInfo<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = 2 * num_passes;
    VkQueryPool pool = VK_NULL_HANDLE;
    CheckVk(vkCreateQueryPool(device_, &info, nullptr, &pool), "vkCreateQueryPool");
    pool_ = UniqueQueryPool(device_, pool);
}

void GpuTimestamps::RecordReset(VkCommandBuffer cmd) const {
    if (pool_) vkCmdResetQueryPool(cmd, pool_.Get(), 0, 2 * num_passes_);
}

void GpuTimestamps::RecordBegin(VkCommandBuffer cmd, uint32_t pass) const {
    if (pool_ && pass < num_passes_) {
        vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool_.Get(), 2 * pass);
    }
}

void GpuTimestamps::RecordEnd(VkCommandBuffer cmd, uint32_t pass) const {
    if (pool_ && pass < num_passes_) {
        vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, pool_.Get(), 2 * pass + 1);
    }
}

std::vector<double> GpuTimestamps::ReadMilliseconds() const {
    std::vector<double> ms(num_passes_, -1.0);
    if (!pool_) return ms;
    // Pairs of (value, availability): passes not recorded this frame stay unavailable,
    // which VK_NOT_READY reports without being an error.
    std::vector<uint64_t> results(4 * num_passes_, 0);
    const VkResult result = vkGetQueryPoolResults(
        device_, pool_.Get(), 0, 2 * num_passes_, results.size() * sizeof(uint64_t), results.data(),
        2 * sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT);
    if (result != VK_SUCCESS && result != VK_NOT_READY) {
        CheckVk(result, "vkGetQueryPoolResults");
    }
    for (uint32_t pass = 0; pass < num_passes_; ++pass) {
        const uint64_t* begin = &results[4 * pass];
        const uint64_t* end = &results[4 * pass + 2];
        if (begin[1] == 0 || end[1] == 0) continue;
        const uint64_t ticks = ((end[0] & valid_mask_) - (begin[0] & valid_mask_)) & valid_mask_;
        ms[pass] = static_cast<double>(ticks) * period_ns_ * 1e-6;
    }
    return ms;
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
