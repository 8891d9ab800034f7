#include "open3d/visualization/rendering/gaussian_splat/vulkan/RadixSort.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <string>

#include "GaussianSplatRadixSortContract.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/CommandTally.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/ComputePipeline.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/EmbeddedShaders.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

namespace {

using namespace shader;  // the contract's constants and structs

static_assert(kErrorEntriesDropped == rendering::kEntriesDropped);
static_assert(kErrorCountsClamped == rendering::kCountsClamped);
static_assert(uint64_t(kRadixSortBins) * (RadixSort::kMaxCount / kRadixSortBlockSize + 1) <
                  (uint64_t(1) << 31),
              "histogram indices of the largest sort fit a uint");
static_assert(offsetof(RadixSortParams, dispatch_x) == offsetof(VkDispatchIndirectCommand, x) &&
                  offsetof(RadixSortParams, dispatch_z) == offsetof(VkDispatchIndirectCommand, z),
              "params start with the indirect dispatch arguments");

VkDeviceSize Words(uint64_t n) { return VkDeviceSize(std::max<uint64_t>(n, 1)) * 4; }

// Shared memory of radix_sort_scatter.comp: per-digit first position and output shift,
// per-subgroup counts (two digits per word), the scan's subgroup sums, and the reordered
// keys and values.
uint64_t ScatterSharedBytes(uint32_t max_subgroups, uint32_t local_capacity) {
    const uint64_t words = 2 * kRadixSortBins + uint64_t(max_subgroups) * (kRadixSortBins / 2) +
                           max_subgroups + 2 * uint64_t(local_capacity);
    return 4 * words;
}

}  // namespace

namespace {

// The one sweep on GPUs: on the H100 it took 0.03-0.06 ms off every frame and its suites
// passed there (docs/perf/h100.md "One-sweep against multi-pass radix sort"). CPU devices keep
// the multi-pass sort: a look-back waits on blocks that lavapipe may run on the same thread.
RadixSort::Algorithm ChooseAlgorithm(RadixSort::Algorithm requested, bool cpu_device) {
    if (requested != RadixSort::Algorithm::kDefault) return requested;
    if (const char* env = std::getenv("OPEN3D_RADIX_SORT"); env != nullptr && *env != '\0') {
        const std::string value = env;
        if (value == "onesweep") return RadixSort::Algorithm::kOneSweep;
        if (value == "multipass") return RadixSort::Algorithm::kMultiPass;
        core::ThrowError("OPEN3D_RADIX_SORT is '{}': use onesweep or multipass (or unset it)",
                         value);
    }
    return cpu_device ? RadixSort::Algorithm::kMultiPass : RadixSort::Algorithm::kOneSweep;
}

}  // namespace

RadixSort::RadixSort(const VulkanContext& context, Algorithm algorithm, RadixSortOptions options)
    : context_(&context) {
    const auto& info = context.GetDeviceInfo();
    algorithm_ = ChooseAlgorithm(algorithm, info.type == "CPU");
    const uint32_t min_subgroup = kRadixSortWorkgroupSize / kRadixSortMaxSubgroups;
    if (info.min_subgroup_size < min_subgroup) {
        core::ThrowError(
            "Vulkan: the radix sort needs subgroups of at least {} invocations; {} "
            "may use {}",
            min_subgroup, info.name, info.min_subgroup_size);
    }
    set_layout_ = CreateStorageBufferPushLayout(context, kRadixSortNumBindings);
    pipeline_layout_ =
        CreatePipelineLayout(context, set_layout_.Get(), sizeof(RadixSortPushConstants));
    VkPipelineLayout layout = pipeline_layout_.Get();
    // Shared arrays sized for the most subgroups a workgroup can have on this device; the
    // scatter reorders each block in shared memory where its arrays fit.
    struct {
        uint32_t max_subgroups;
        uint32_t local_capacity;
        uint32_t odd_blocks_aggregate_only;
        uint32_t run_capacity;
    } constants{kRadixSortWorkgroupSize / info.min_subgroup_size, 1u,
                options.odd_blocks_aggregate_only ? 1u : 0u, 1u};
    constants.local_capacity = ScatterSharedBytes(constants.max_subgroups, kRadixSortBlockSize) <=
                                       info.max_compute_shared_memory
                                   ? kRadixSortBlockSize
                                   : 1u;
    local_reorder_ = constants.local_capacity > 1u;
    const std::array<VkSpecializationMapEntry, 4> entries{
        {{kSpecRadixSortSubgroups, 0, sizeof(uint32_t)},
         {kSpecRadixSortLocalCapacity, sizeof(uint32_t), sizeof(uint32_t)},
         {kSpecRadixSweepOddBlocksAggregateOnly, 2 * sizeof(uint32_t), sizeof(uint32_t)},
         {kSpecRadixSortRunCapacity, 3 * sizeof(uint32_t), sizeof(uint32_t)}}};
    const VkSpecializationInfo specialization{static_cast<uint32_t>(entries.size()), entries.data(),
                                              sizeof(constants), &constants};
    const auto create = [&](std::span<const uint32_t> spirv, const char* name) {
        return CreateComputePipeline(context, layout, spirv, name, &specialization);
    };
    setup_ = create(spirv::kRadixSortSetup, "radix_sort_setup");
    histogram_ = create(spirv::kRadixSortHistogram, "radix_sort_histogram");
    scan_ = create(spirv::kRadixSortScan, "radix_sort_scan");
    scatter_ = create(spirv::kRadixSortScatter, "radix_sort_scatter");
    copy_ = create(spirv::kRadixSortCopy, "radix_sort_copy");
    if (algorithm_ == Algorithm::kOneSweep) {
        sweep_histogram_ = create(spirv::kRadixSortSweepHistogram, "radix_sort_sweep_histogram");
        sweep_scatter_ = create(spirv::kRadixSortSweepScatter, "radix_sort_sweep_scatter");
        // Run bounds need the block's keys in sorted order: the local reorder's, or an array of
        // their own where the device has no room for that (lavapipe: 8 KiB more).
        constants.run_capacity = local_reorder_ ? 1u : kRadixSortBlockSize;
        sweep_scatter_runs_ =
            create(spirv::kRadixSortSweepScatter, "radix_sort_sweep_scatter (run bounds)");
    }
}

void RadixSort::RecordClearSweepState(VkCommandBuffer cmd, const BufferRange& sweep_state) {
    vkCmdFillBuffer(cmd, sweep_state.buffer, sweep_state.offset, sizeof(RadixSweepState), 0u);
}

uint32_t RadixSort::MaxCountFor(uint64_t max_storage_buffer_range) {
    // Keys and values are bound whole. The histogram, 1 + blocks uints per digit, takes about
    // half a byte per pair, so it never binds first.
    const uint64_t by_keys = max_storage_buffer_range / 4;
    return static_cast<uint32_t>(std::min<uint64_t>(by_keys, kMaxCount));
}

uint32_t RadixSort::MaxCountFor(const VulkanDeviceInfo& info) {
    return MaxCountFor(info.max_storage_buffer_range);
}

uint32_t RadixSort::GetMaxCount() const { return MaxCountFor(context_->GetDeviceInfo()); }

uint32_t RadixSort::GetMaxGroupsX() const {
    return context_->GetDeviceInfo().max_compute_workgroups_x;
}

RadixSortStorageRequirements RadixSort::GetStorageRequirements(uint32_t max_count) {
    if (max_count > kMaxCount) {
        core::ThrowError("RadixSort: max_count {} exceeds the supported {}", max_count, kMaxCount);
    }
    RadixSortStorageRequirements requirements;
    requirements.keys_alt_bytes = Words(max_count);
    requirements.values_alt_bytes = Words(max_count);
    // The multi-pass sort's digit totals and per-block counts, or the one-sweep sort's two
    // tables of look-back status words.
    // The most blocks radix_sort_setup.comp can choose for any count <= max_count.
    const uint64_t blocks = RadixSortMaxBlocks(max_count, kRadixSortTargetBlocks);
    requirements.histogram_bytes =
        Words(std::max(kRadixSortBins + kRadixSortBins * blocks, 2 * kRadixSortBins * blocks));
    requirements.params_bytes = sizeof(RadixSortParams);
    requirements.sweep_state_bytes = sizeof(RadixSweepState);
    return requirements;
}

namespace {

// A uint the GPU reads from any 4-byte aligned offset (see the binding in Record).
void RequireCountRange(const BufferRange& range, const char* name) {
    if (range.buffer == VK_NULL_HANDLE || range.offset % 4 != 0) {
        core::ThrowError("RadixSort: {} needs a buffer and a 4-byte aligned offset", name);
    }
}

}  // namespace

void RadixSort::CheckArguments(const BufferRange& keys, const BufferRange& values,
                               const RadixSortScratch& scratch, const BufferRange& count,
                               uint32_t max_count, uint32_t num_bits) const {
    if (num_bits > 32) core::ThrowError("RadixSort: num_bits is {}, at most 32", num_bits);
    if (max_count > GetMaxCount()) {
        const VulkanDeviceInfo& info = context_->GetDeviceInfo();
        core::ThrowError(
            "RadixSort: max_count {} exceeds the {} pairs {} sorts (its keys within one "
            "binding of maxStorageBufferRange {} bytes, at most {})",
            max_count, GetMaxCount(), info.name, info.max_storage_buffer_range, kMaxCount);
    }
    const RadixSortStorageRequirements need = GetStorageRequirements(max_count);
    const VkDeviceSize alignment = context_->GetDeviceInfo().min_storage_buffer_offset_alignment;
    struct Check {
        const char* name;
        const BufferRange& range;
        VkDeviceSize bytes;
    };
    const std::array<Check, 7> checks{
        {{"keys", keys, Words(max_count)},
         {"values", values, Words(max_count)},
         {"scratch.keys_alt", scratch.keys_alt, need.keys_alt_bytes},
         {"scratch.values_alt", scratch.values_alt, need.values_alt_bytes},
         {"scratch.histogram", scratch.histogram, need.histogram_bytes},
         {"scratch.params", scratch.params, need.params_bytes},
         {"scratch.sweep_state", scratch.sweep_state, need.sweep_state_bytes}}};
    for (const Check& check : checks) {
        if (check.range.buffer == VK_NULL_HANDLE) {
            core::ThrowError("RadixSort: {} has no buffer", check.name);
        }
        if (check.range.offset % alignment != 0) {
            core::ThrowError(
                "RadixSort: {} offset {} is not a multiple of "
                "minStorageBufferOffsetAlignment {}",
                check.name, check.range.offset, alignment);
        }
        if (check.range.size != VK_WHOLE_SIZE && check.range.size < check.bytes) {
            core::ThrowError("RadixSort: {} holds {} bytes, {} are needed for max_count {}",
                             check.name, check.range.size, check.bytes, max_count);
        }
    }
    RequireCountRange(count, "count");
}

uint32_t RadixSort::GetTargetBlocks() const {
    // GPUs want about one wave of blocks; a CPU device (lavapipe) runs workgroups on a few
    // threads, where every block's fixed cost (digit offsets, slot scan) is pure overhead:
    // 16 blocks keep it as fast as the fixed 4096-element blocks were.
    return context_->GetDeviceInfo().type == "CPU" ? 16u : kRadixSortTargetBlocks;
}

void RadixSort::BindBuffers(VkCommandBuffer cmd, const RadixSortScratch& scratch,
                            const BufferRange& count_in, uint32_t max_count,
                            const BufferRange& keys_in, const BufferRange& values_in,
                            const BufferRange& keys_out, const BufferRange& values_out,
                            const RunBounds* runs) const {
    // The count may sit at any 4-byte offset: bound from the aligned offset below it, the
    // uint indexed with a push constant (count_index).
    const VkDeviceSize alignment = context_->GetDeviceInfo().min_storage_buffer_offset_alignment;
    std::array<VkDescriptorBufferInfo, kRadixSortNumBindings> buffers{};
    buffers[kRadixSortParamsBinding] = {scratch.params.buffer, scratch.params.offset,
                                        sizeof(RadixSortParams)};
    buffers[kRadixSortCountBinding] = {
        count_in.buffer, count_in.offset - count_in.offset % alignment, VK_WHOLE_SIZE};
    buffers[kRadixSortKeysInBinding] = {keys_in.buffer, keys_in.offset, Words(max_count)};
    buffers[kRadixSortValuesInBinding] = {values_in.buffer, values_in.offset, Words(max_count)};
    buffers[kRadixSortKeysOutBinding] = {keys_out.buffer, keys_out.offset, Words(max_count)};
    buffers[kRadixSortValuesOutBinding] = {values_out.buffer, values_out.offset, Words(max_count)};
    buffers[kRadixSortHistogramBinding] = {scratch.histogram.buffer, scratch.histogram.offset,
                                           GetStorageRequirements(max_count).histogram_bytes};
    buffers[kRadixSortSweepStateBinding] = {scratch.sweep_state.buffer, scratch.sweep_state.offset,
                                            sizeof(RadixSweepState)};
    // Without run bounds the binding is never written but must name a buffer: the params.
    buffers[kRadixSortRunBoundsBinding] =
        runs ? VkDescriptorBufferInfo{runs->ranges.buffer, runs->ranges.offset, runs->ranges.size}
             : buffers[kRadixSortParamsBinding];
    std::array<VkWriteDescriptorSet, kRadixSortNumBindings> writes{};
    for (uint32_t i = 0; i < kRadixSortNumBindings; ++i) {
        writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &buffers[i];
    }
    context_->GetCmdPushDescriptorSet()(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_layout_.Get(),
                                        0, kRadixSortNumBindings, writes.data());
}

void RadixSort::Record(VkCommandBuffer cmd, const BufferRange& keys, const BufferRange& values,
                       const RadixSortScratch& scratch, const BufferRange& count,
                       uint32_t max_count, uint32_t num_bits, Params params,
                       const DropMaxKeys* drop, PassCount pass_count, Output output,
                       const RunBounds* runs) const {
    CheckArguments(keys, values, scratch, count, max_count, num_bits);
    if (drop) RequireCountRange(drop->kept_count, "kept_count");
    if (runs && (runs->ranges.buffer == VK_NULL_HANDLE || runs->num_keys == 0 || num_bits == 0)) {
        core::ThrowError("RadixSort: run bounds need a buffer, at least one key and key bits");
    }
    if (GetNumPasses(num_bits) == 0) return;  // no key bits: every order is sorted
    // Status words hold counts below 2^30 (kRadixSweepValueMask).
    if (algorithm_ == Algorithm::kOneSweep && max_count <= kRadixSweepValueMask) {
        RecordOneSweep(cmd, keys, values, scratch, count, max_count, num_bits, params, drop, output,
                       runs);
    } else {
        if (scratch.sweep_histogram_written || runs) {
            core::ThrowError(
                "RadixSort: a producer-written histogram and run bounds need the one-sweep sort");
        }
        RecordMultiPass(cmd, keys, values, scratch, count, max_count, num_bits, params, drop,
                        pass_count, output);
    }
}

uint32_t RadixSort::CountIndex(const BufferRange& count) const {
    const VkDeviceSize alignment = context_->GetDeviceInfo().min_storage_buffer_offset_alignment;
    return static_cast<uint32_t>((count.offset % alignment) / 4);
}

RadixSortPushConstants RadixSort::PushConstantsFor(const BufferRange& count, uint32_t max_count,
                                                   uint32_t num_bits, Output output) const {
    RadixSortPushConstants push{};
    push.count_index = CountIndex(count);
    push.max_count = max_count;
    push.target_blocks = GetTargetBlocks();
    push.num_passes = GetNumPasses(num_bits);
    push.values_only = output == Output::kValuesOnly ? 1u : 0u;
    push.max_groups_x = GetMaxGroupsX();
    push.num_bits = num_bits;
    return push;
}

void RadixSort::RecordMultiPass(VkCommandBuffer cmd, const BufferRange& keys,
                                const BufferRange& values, const RadixSortScratch& scratch,
                                const BufferRange& count, uint32_t max_count, uint32_t num_bits,
                                Params params, const DropMaxKeys* drop, PassCount pass_count,
                                Output output) const {
    const uint32_t num_passes = GetNumPasses(num_bits);
    // A range can only save passes after the first.
    const bool by_range = pass_count == PassCount::kFromKeyRange && num_passes > 1;
    BufferRange count_in = count;  // what the setup dispatch reads
    RadixSortPushConstants push = PushConstantsFor(count, max_count, num_bits, output);

    const VkPipelineLayout layout = pipeline_layout_.Get();
    const auto bind = [&](const BufferRange& keys_in, const BufferRange& values_in,
                          const BufferRange& keys_out, const BufferRange& values_out) {
        BindBuffers(cmd, scratch, count_in, max_count, keys_in, values_in, keys_out, values_out);
    };
    const auto push_constants = [&]() {
        vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
    };
    // Every dispatch reads what the previous one wrote, including indirect arguments.
    const auto barrier = [&]() { RecordComputeToComputeAndIndirect(cmd); };
    const VkBuffer params_buffer = scratch.params.buffer;
    const VkDeviceSize params_offset = scratch.params.offset;

    const auto setup = [&]() {
        bind(keys, values, scratch.keys_alt, scratch.values_alt);
        push_constants();
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, setup_.Get());
        RecordDispatch(cmd, 1, 1, 1);
        barrier();
    };
    if (params == Params::kSetupPass) setup();
    // From here the first pass's histogram finds the kept keys' range and the setup after
    // it reads the range (the setup above must not: the range is not known yet).
    push.key_range = by_range ? 1u : 0u;

    if (max_count == 0) return;  // params now say count 0; nothing to move

    // With a range, the passes after the first and the copy take their sizes from the
    // setup after the first pass (zero groups for the passes it skips); else they all run.
    const bool copies = by_range || num_passes % 2 == 1;
    const auto pass_args = [&](VkDeviceSize member, uint32_t pass) {
        return by_range && pass > 0 ? params_offset + member + pass * sizeof(uvec4) : params_offset;
    };
    for (uint32_t pass = 0; pass < num_passes; ++pass) {
        // Ping-pong: even passes read the caller's buffers, odd passes the scratch.
        if (pass % 2 == 0) {
            bind(keys, values, scratch.keys_alt, scratch.values_alt);
        } else {
            bind(scratch.keys_alt, scratch.values_alt, keys, values);
        }
        push.shift = pass * kRadixSortDigitBits;
        push.digit_bits = std::min(kRadixSortDigitBits, num_bits - push.shift);
        push.drop_max_keys = pass == 0 && drop ? 1u : 0u;
        push_constants();
        const VkDeviceSize blocks = pass_args(offsetof(RadixSortParams, pass_blocks), pass);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, histogram_.Get());
        RecordDispatchIndirect(cmd, params_buffer, blocks);
        barrier();
        // One workgroup per digit; rows of digits above digit_bits are all zero.
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, scan_.Get());
        if (by_range && pass > 0) {
            RecordDispatchIndirect(cmd, params_buffer,
                                   pass_args(offsetof(RadixSortParams, pass_rows), pass));
        } else {
            RecordDispatch(cmd, kRadixSortBins, 1, 1);
        }
        barrier();
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, scatter_.Get());
        RecordDispatchIndirect(cmd, params_buffer, blocks);
        if (pass + 1 < num_passes || copies) barrier();
        if (pass == 0 && (drop || by_range)) {
            // The kept pairs are packed at the front of the scratch: the later passes (and
            // the copy of an odd pass count) sort only them. The range decides which of
            // the later passes run.
            if (drop) count_in = drop->kept_count;
            push.count_index = CountIndex(count_in);
            push.drop_max_keys = 0;
            setup();
        }
    }
    if (copies) {
        bind(scratch.keys_alt, scratch.values_alt, keys, values);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, copy_.Get());
        RecordDispatchIndirect(
            cmd, params_buffer,
            by_range ? params_offset + offsetof(RadixSortParams, copy_blocks) : params_offset);
    }
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
