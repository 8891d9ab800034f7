// GPU radix sort of (uint32 key, uint32 value) pairs, a recorder (docs/DESIGN.md "Code rules"): the
// caller allocates the scratch buffers from GetStorageRequirements and Record() only
// records commands. The element count is read on the GPU from the producer's buffer.
//
// Algorithm (docs/radix-sort.md): LSD, 8-bit digits, ceil(num_bits / 8) passes, blocks of
// 256..2048 elements (at most kRadixSortTargetBlocks of them while 2048-element blocks are not
// needed) dispatched indirectly with the block count a setup shader or the producer writes.
// Two ways to run the passes (Algorithm):
// - multi-pass: per pass histogram (per-block digit counts) -> scan (one workgroup per digit)
//   -> scatter (stable in-workgroup ranking from subgroup ballots), fewer passes with
//   PassCount::kFromKeyRange;
// - one sweep: one histogram of every pass's digits, then one scatter per pass in which each
//   block finds its offsets by decoupled look-back on the blocks before it.
// Stable for any subgroup size; keys bits at and above num_bits are carried but do not affect
// the order.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

#include "GaussianSplatRadixSortContract.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class VulkanContext;
struct VulkanDeviceInfo;

/// Bytes and usage of the scratch buffers a sort of up to max_count pairs needs.
struct RadixSortStorageRequirements {
    VkDeviceSize keys_alt_bytes = 0;     ///< uint32 [max_count]
    VkDeviceSize values_alt_bytes = 0;   ///< uint32 [max_count]
    VkDeviceSize histogram_bytes = 0;    ///< uint32 [256 + 256 * max blocks]
    VkDeviceSize params_bytes = 0;       ///< shader::RadixSortParams
    VkDeviceSize sweep_state_bytes = 0;  ///< shader::RadixSweepState
    /// Usage of keys_alt, values_alt and histogram.
    VkBufferUsageFlags scratch_usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    /// Usage of params (it holds the indirect dispatch arguments).
    VkBufferUsageFlags params_usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
    /// Usage of sweep_state (it is cleared with vkCmdFillBuffer).
    VkBufferUsageFlags sweep_state_usage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
};

/// Scratch ranges, each at least as large as required and with an offset that is a
/// multiple of minStorageBufferOffsetAlignment. They may share one buffer, not overlap.
struct RadixSortScratch {
    BufferRange keys_alt;
    BufferRange values_alt;
    BufferRange histogram;
    /// After the sort (unless num_bits == 0, which records nothing), shader::RadixSortParams:
    /// `count` is the number sorted and `flags` has kErrorCountsClamped when the producer's
    /// count exceeded max_count.
    BufferRange params;
    /// shader::RadixSweepState: the one-sweep sort's digit histogram and block counters,
    /// zero before each sort (the multi-pass sort binds it without reading it).
    BufferRange sweep_state;
    /// true: the caller zeroed sweep_state (RecordClearSweepState) and made that visible to
    /// COMPUTE_SHADER reads and writes, e.g. with its other transfers at the start of a
    /// frame. false: a one-sweep Record clears it itself, behind a barrier of its own.
    bool sweep_state_cleared = false;
    /// true (one sweep only, with params kWrittenByProducer): the producer also added every
    /// pass's digit counts of the kept pairs (all `count` of them, or those a DropMaxKeys
    /// keeps) to sweep_state's histogram and zeroed the first pass's status rows (words
    /// [0, num_blocks * 256) of `histogram`), as the sort's histogram dispatch would, so
    /// Record skips that dispatch.
    bool sweep_histogram_written = false;
};

/// Test switches of the one-sweep scatter.
struct RadixSortOptions {
    /// Odd blocks publish only their own counts, never their inclusive prefix, so every
    /// look-back walks past them (covers the aggregate path where workgroups run in order).
    bool odd_blocks_aggregate_only = false;
};

class RadixSort {
public:
    /// Largest max_count on any device: the sort's uint arithmetic (element and histogram
    /// indices, RadixSortParamsFor) stays below 2^31. A device takes at most GetMaxCount().
    static constexpr uint32_t kMaxCount = 1u << 30;
    /// Largest max_count of a device with the given limit: the keys and values within one
    /// storage binding (maxStorageBufferRange: 2^27 bytes on lavapipe, 2^32 - 1 on NVIDIA),
    /// and at most kMaxCount. The blocks' workgroups are laid out in rows where they pass
    /// maxComputeWorkGroupCount[0] (DispatchGridFor), so that limit bounds nothing.
    static uint32_t MaxCountFor(uint64_t max_storage_buffer_range);
    /// MaxCountFor a device's reported limits: 33,554,432 pairs on lavapipe, 1,073,741,823 on
    /// an H200.
    static uint32_t MaxCountFor(const VulkanDeviceInfo& info);
    /// MaxCountFor this sorter's device.
    uint32_t GetMaxCount() const;
    /// The device's maxComputeWorkGroupCount[0], which RadixSortParamsFor takes: producers
    /// that write the parameters themselves pass it.
    uint32_t GetMaxGroupsX() const;

    /// How the passes run (the class comment). kDefault: the one sweep on GPUs, the multi-pass
    /// sort on CPU devices, unless the environment variable OPEN3D_RADIX_SORT=onesweep (or
    /// =multipass) says otherwise (docs/radix-sort.md). On CPU devices (lavapipe) the one sweep
    /// is for tests only: a look-back may wait for a workgroup whose thread the OS has
    /// descheduled, and lavapipe ends a loop after 65,535 iterations
    /// (docs/environment-notes.md).
    enum class Algorithm { kDefault, kMultiPass, kOneSweep };

    /// Creates the pipelines. Throws core::Open3DError when the device's subgroups can be
    /// smaller than 8 invocations (the shaders size shared arrays by subgroup count), and for
    /// an OPEN3D_RADIX_SORT value it does not know.
    explicit RadixSort(const VulkanContext& context, Algorithm algorithm = Algorithm::kDefault,
                       RadixSortOptions options = {});
    /// kMultiPass or kOneSweep: what Record runs (a one-sweep sorter still runs the
    /// multi-pass sort for a max_count whose counts would not fit a status word, 2^30 or more).
    Algorithm GetAlgorithm() const { return algorithm_; }
    /// Zeroes a one-sweep sort's state (a transfer write: the caller barriers before the sort
    /// and sets RadixSortScratch::sweep_state_cleared).
    static void RecordClearSweepState(VkCommandBuffer cmd, const BufferRange& sweep_state);

    /// Scratch sizes for up to `max_count` pairs. Throws when max_count > kMaxCount (Record
    /// checks the device's GetMaxCount).
    static RadixSortStorageRequirements GetStorageRequirements(uint32_t max_count);
    /// Passes for `num_bits` key bits: ceil(num_bits / 8).
    static uint32_t GetNumPasses(uint32_t num_bits) { return (num_bits + 7u) / 8u; }
    /// The block count the sort aims at on this device (RadixSortParamsFor's target_blocks).
    uint32_t GetTargetBlocks() const;
    /// Whether the scatter reorders each block in shared memory before writing it (where
    /// the device's shared memory holds a block; lavapipe's 32 KiB does not).
    bool UsesLocalReorder() const { return local_reorder_; }

    /// Who writes `scratch.params` before the passes.
    enum class Params {
        kSetupPass,  ///< the sort's own setup dispatch, from the GPU count at `count`
        /// The producer already wrote RadixSortParamsFor(count, max_count, GetTargetBlocks(),
        /// GetMaxGroupsX())
        /// (from a shader, or from the host with vkCmdUpdateBuffer) and made it visible to
        /// COMPUTE_SHADER and DRAW_INDIRECT reads: one dispatch fewer. `count` is not read
        /// (but by the setup after the first pass of kFromKeyRange without a DropMaxKeys).
        kWrittenByProducer,
    };

    /// Optional for Record: the first pass leaves out every pair whose key is
    /// kRadixSortDroppedKey (0xFFFFFFFF), and the later passes sort the kept pairs only.
    /// Their number is read on the GPU at `kept_count` by a setup dispatch after the first
    /// pass; the caller counts them (it must be the number of other keys among the first
    /// `count` pairs). Afterwards the first kept_count pairs are the sorted kept pairs;
    /// what lies past them is unspecified. Geometry stage drops its culled splats this way, so
    /// three of the depth sort's four passes see only the visible ones.
    struct DropMaxKeys {
        BufferRange kept_count;  // uint written on the GPU; 4-byte alignment is enough
    };

    /// How many passes run. kFromKeyRange: the first pass's histogram also finds the
    /// smallest and largest kept key (one atomic pair per block), the pairs are sorted by
    /// key - base, base = that minimum rounded down to a multiple of 256 (the same order),
    /// and only the passes up to the highest non-zero digit of max - base run: a setup
    /// dispatch after the first pass gives the others zero workgroups and copies an odd
    /// number of passes back to `keys` and `values`. `scratch.params` then has key_min,
    /// key_max and range_passes. The one-sweep sort ignores it: every pass runs, and a pass
    /// whose kept keys all share their digit (from the histogram it knows in advance) copies.
    /// Geometry stage's depth keys (float bits) of a frame whose farthest visible splat is less
    /// than 2 to 4 times as far as the nearest span less than 2^24: three passes instead of four.
    enum class PassCount {
        kAll,  ///< ceil(num_bits / 8)
        kFromKeyRange,
    };

    /// What the caller reads afterwards. kValuesOnly: the keys are left unspecified, and
    /// the last pass that runs and the copy write no keys (but the first pass of a
    /// kFromKeyRange sort, which runs before the range is known). The geometry stage's depth
    /// sort reads only the splat indices (docs/perf/h200.md has the time).
    enum class Output {
        kKeysAndValues,
        kValuesOnly,
    };

    /// Optional for Record (one sweep only): the last pass also leaves each key's run of the
    /// sorted output in `ranges`, as two uints per key from uint `word_offset` on: begin,
    /// lowered with atomicMin, and end, raised with atomicMax, for every key below `num_keys`
    /// (others, e.g. filler keys, are skipped). The caller sets every pair to (0xFFFFFFFF, 0)
    /// beforehand, so a key without pairs keeps begin > end. Replaces a pass over the sorted
    /// keys (the geometry stage's tile ranges).
    struct RunBounds {
        BufferRange ranges;
        uint32_t word_offset = 0;
        uint32_t num_keys = 0;
    };
    /// Records a stable sort of the first `count` pairs of (keys, values) by the low
    /// `num_bits` (0..32) bits of the keys, count = min(the uint at `count`, max_count).
    /// The result is in `keys` and `values` (with `drop`: see DropMaxKeys).
    ///
    /// Synchronisation: before Record, the caller makes its writes of keys, values and
    /// count visible to COMPUTE_SHADER reads (and orders earlier uses of the scratch);
    /// after it, results are COMPUTE_SHADER storage writes for the caller to barrier.
    /// `keys`/`values` offsets must be multiples of minStorageBufferOffsetAlignment;
    /// `count` only needs 4-byte alignment. Throws core::Open3DError on misuse, and for a
    /// max_count above GetMaxCount().
    void Record(VkCommandBuffer cmd,
                const BufferRange& keys,    // uint32 [max_count], sorted in place
                const BufferRange& values,  // uint32 [max_count], permuted with keys
                const RadixSortScratch& scratch,
                const BufferRange& count,  // uint32 written on the GPU by the producer
                uint32_t max_count, uint32_t num_bits, Params params = Params::kSetupPass,
                const DropMaxKeys* drop = nullptr, PassCount pass_count = PassCount::kAll,
                Output output = Output::kKeysAndValues, const RunBounds* runs = nullptr) const;

private:
    // The index of a count's uint within its binding, which starts at the aligned offset below
    // it (BindBuffers): the push constant count_index.
    uint32_t CountIndex(const BufferRange& count) const;
    // The push constants every dispatch of a sort starts from (the passes set shift,
    // digit_bits and drop_max_keys).
    shader::RadixSortPushConstants PushConstantsFor(const BufferRange& count, uint32_t max_count,
                                                    uint32_t num_bits, Output output) const;
    // Pushes the sort's bindings: the given key/value buffers in and out, the scratch, and
    // the count at its aligned binding.
    void BindBuffers(VkCommandBuffer cmd, const RadixSortScratch& scratch,
                     const BufferRange& count_in, uint32_t max_count, const BufferRange& keys_in,
                     const BufferRange& values_in, const BufferRange& keys_out,
                     const BufferRange& values_out, const RunBounds* runs = nullptr) const;
    void RecordMultiPass(VkCommandBuffer cmd, const BufferRange& keys, const BufferRange& values,
                         const RadixSortScratch& scratch, const BufferRange& count,
                         uint32_t max_count, uint32_t num_bits, Params params,
                         const DropMaxKeys* drop, PassCount pass_count, Output output) const;
    void RecordOneSweep(VkCommandBuffer cmd, const BufferRange& keys, const BufferRange& values,
                        const RadixSortScratch& scratch, const BufferRange& count,
                        uint32_t max_count, uint32_t num_bits, Params params,
                        const DropMaxKeys* drop, Output output, const RunBounds* runs) const;
    void CheckArguments(const BufferRange& keys, const BufferRange& values,
                        const RadixSortScratch& scratch, const BufferRange& count,
                        uint32_t max_count, uint32_t num_bits) const;

    const VulkanContext* context_;  // outlives the sorter
    UniqueDescriptorSetLayout set_layout_;
    UniquePipelineLayout pipeline_layout_;
    UniquePipeline setup_;
    UniquePipeline histogram_;
    UniquePipeline scan_;
    UniquePipeline scatter_;
    UniquePipeline copy_;
    UniquePipeline sweep_histogram_;
    UniquePipeline sweep_scatter_;
    UniquePipeline sweep_scatter_runs_;  // writes RunBounds in its last pass
    Algorithm algorithm_ = Algorithm::kMultiPass;
    bool local_reorder_ = false;
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
