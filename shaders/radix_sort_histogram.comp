#version 460
// Pass 1 of a digit: per-block digit counts, stored digit-major so that one exclusive scan
// per digit row (radix_sort_scan.comp) gives every block its output offset within a digit.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "radix_sort_common.glsl"

layout(local_size_x = kRadixSortWorkgroupSize) in;

// Written only by the first pass of PassCount::kFromKeyRange (key_min, key_max).
layout(std430, set = 0, binding = kRadixSortParamsBinding) buffer ParamsBlock {
    RadixSortParams params;
};
layout(std430, set = 0, binding = kRadixSortKeysInBinding) readonly buffer KeysBlock {
    uint keys_in[];
};
// [kRadixSortBins] digit totals, then [kRadixSortBins][num_blocks] block counts.
layout(std430, set = 0, binding = kRadixSortHistogramBinding) writeonly buffer HistogramBlock {
    uint histogram[];
};

shared uint s_counts[kRadixSortBins];
shared uint s_key_min;  // this block's kept keys, with PassCount::kFromKeyRange
shared uint s_key_max;

void main() {
    uint block = FlatWorkGroupIndex();
    if (block >= params.num_blocks) return;  // a spare workgroup of the grid's last row
    uint local = gl_LocalInvocationIndex;
    g_key_base = params.key_base;
    s_counts[local] = 0u;
    // The range of the kept keys is found once, by the first pass (digit 0).
    bool track_range = pc.key_range != 0u && pc.shift == 0u;
    if (track_range && local == 0u) {
        s_key_min = 0xFFFFFFFFu;
        s_key_max = 0u;
    }
    barrier();
    uint count = params.count;
    uint block_size = params.block_size;
    uint block_begin = block * block_size;
    uint chunks = block_size / kRadixSortWorkgroupSize;  // uniform, 1..8
    // All loads first, so that they are in flight together (one load, then its atomic, per
    // step measured slower: docs/perf/h200.md).
    uint keys[kRadixSortItemsPerInvocation];
    [[unroll]] for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        uint index = block_begin + local + k * kRadixSortWorkgroupSize;
        keys[k] = k < chunks && index < count ? keys_in[index] : 0u;
    }
    uint key_min = 0xFFFFFFFFu;
    uint key_max = 0u;
    [[unroll]] for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        uint index = block_begin + local + k * kRadixSortWorkgroupSize;
        if (k < chunks && index < count && IsKept(keys[k])) {
            atomicAdd(s_counts[DigitOf(keys[k])], 1u);
            key_min = min(key_min, keys[k]);
            key_max = max(key_max, keys[k]);
        }
    }
    if (track_range) {
        // Subgroup, then workgroup, then one global atomic pair per block: same-address
        // global atomics serialise (docs/environment-notes.md).
        key_min = subgroupMin(key_min);
        key_max = subgroupMax(key_max);
        if (subgroupElect()) {
            atomicMin(s_key_min, key_min);
            atomicMax(s_key_max, key_max);
        }
    }
    barrier();
    histogram[kRadixSortBins + local * params.num_blocks + block] = s_counts[local];
    if (track_range && local == 0u && s_key_min <= s_key_max) {
        // A block inside the range recorded so far changes nothing. The recorded values
        // only move outwards, so one read late in this dispatch can only skip atomics
        // that would have been no-ops.
        if (s_key_min < params.key_min) atomicMin(params.key_min, s_key_min);
        if (s_key_max > params.key_max) atomicMax(params.key_max, s_key_max);
    }
}
