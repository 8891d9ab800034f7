// RadixSort::RecordOneSweep: the one-sweep sort's recording (RadixSort.h; shaders
// radix_sort_sweep_histogram.comp and radix_sort_sweep_scatter.comp, docs/radix-sort.md
// "One sweep"). One histogram dispatch, then one scatter dispatch per pass, each pass's
// blocks chained by decoupled look-back instead of a histogram and a scan dispatch of their own.
#include <algorithm>
#include <cstddef>

#include "GaussianSplatRadixSortContract.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/CommandTally.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/RadixSort.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

using namespace shader;  // the contract's constants and structs

void RadixSort::RecordOneSweep(VkCommandBuffer cmd, const BufferRange& keys,
                               const BufferRange& values, const RadixSortScratch& scratch,
                               const BufferRange& count, uint32_t max_count, uint32_t num_bits,
                               Params params, const DropMaxKeys* drop, Output output,
                               const RunBounds* runs) const {
    const uint32_t num_passes = GetNumPasses(num_bits);
    RadixSortPushConstants push = PushConstantsFor(count, max_count, num_bits, output);
    push.sweep = 1u;
    if (runs) {
        push.run_keys = runs->num_keys;
        push.run_offset = runs->word_offset;
    }
    const VkPipelineLayout layout = pipeline_layout_.Get();
    const auto dispatch = [&](VkPipeline pipeline, VkDeviceSize args_member) {
        vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
        RecordDispatchIndirect(cmd, scratch.params.buffer, scratch.params.offset + args_member);
    };

    // The parameters (the setup shader's, from the GPU count, unless the producer wrote
    // them) and a zero state. One barrier covers both.
    bool wrote = false;
    if (!scratch.sweep_state_cleared) {
        RecordClearSweepState(cmd, scratch.sweep_state);
        wrote = true;
    }
    if (params == Params::kSetupPass) {
        BindBuffers(cmd, scratch, count, max_count, keys, values, scratch.keys_alt,
                    scratch.values_alt, runs);
        vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, setup_.Get());
        RecordDispatch(cmd, 1, 1, 1);
        wrote = true;
    }
    if (wrote) {
        RecordMemoryBarrier(
            cmd, VK_PIPELINE_STAGE_2_TRANSFER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
    }
    if (max_count == 0) return;  // params now say count 0; nothing to move

    // Every pass's digit counts (of the kept keys) and the first pass's status rows, unless
    // the producer counted them.
    if (scratch.sweep_histogram_written) {
        if (params != Params::kWrittenByProducer) {
            core::ThrowError(
                "RadixSort: a producer-written histogram needs producer-written parameters");
        }
    } else {
        BindBuffers(cmd, scratch, count, max_count, keys, values, scratch.keys_alt,
                    scratch.values_alt, runs);
        push.drop_max_keys = drop ? 1u : 0u;
        dispatch(sweep_histogram_.Get(), offsetof(RadixSortParams, sweep_histogram_grid));
        // From here every dispatch takes its size from the params made visible above (or by
        // the producer), so the barriers between the passes wait for storage only.
        RecordComputeToCompute(cmd);
    }

    for (uint32_t pass = 0; pass < num_passes; ++pass) {
        // Ping-pong: even passes read the caller's buffers, odd passes the scratch.
        if (pass % 2 == 0) {
            BindBuffers(cmd, scratch, count, max_count, keys, values, scratch.keys_alt,
                        scratch.values_alt, runs);
        } else {
            BindBuffers(cmd, scratch, count, max_count, scratch.keys_alt, scratch.values_alt, keys,
                        values, runs);
        }
        push.shift = pass * kRadixSortDigitBits;
        push.digit_bits = std::min(kRadixSortDigitBits, num_bits - push.shift);
        push.drop_max_keys = pass == 0 && drop ? 1u : 0u;
        // Every pass takes the first pass's grid; blocks past the kept pairs end at once.
        dispatch(runs && pass + 1 == num_passes ? sweep_scatter_runs_.Get() : sweep_scatter_.Get(),
                 offsetof(RadixSortParams, dispatch_x));
        if (pass + 1 < num_passes || num_passes % 2 == 1) RecordComputeToCompute(cmd);
    }
    if (num_passes % 2 == 1) {
        // The sorted pairs are in the scratch: copy the kept ones back.
        BindBuffers(cmd, scratch, count, max_count, scratch.keys_alt, scratch.values_alt, keys,
                    values);
        push.drop_max_keys = 0;
        dispatch(copy_.Get(), offsetof(RadixSortParams, dispatch_x));
    }
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
