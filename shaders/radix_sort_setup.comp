#version 460
// Reads the element count written on the GPU by the producer, clamps it to max_count,
// chooses the block size and writes the indirect dispatch size of the per-block passes (no
// CPU readback): RadixSortParamsFor in GaussianSplatRadixSortContract.h. RadixSort::GetStorageRequirements
// bounds the block count the same way.
// With PassCount::kFromKeyRange (the setup after the first pass): the kept keys' (min, max),
// which the first pass's histogram found, decide how many passes are needed. Keys are
// sorted by key - key_base, key_base = min rounded down to a multiple of kRadixSortBins (so
// the first pass, which sorted by the key's own low digit, agrees), and the passes past the
// highest non-zero digit of max - key_base would move every pair to where it is: they get
// zero workgroups, and an odd number of passes run is copied back to the caller's buffers.
#extension GL_GOOGLE_include_directive : require
#include "radix_sort_common.glsl"

layout(local_size_x = 1) in;

layout(std430, set = 0, binding = kRadixSortParamsBinding) buffer ParamsBlock {
    RadixSortParams params;
};
layout(std430, set = 0, binding = kRadixSortCountBinding) readonly buffer CountBlock {
    uint counts[];
};

void main() {
    RadixSortParams p = RadixSortParamsFor(counts[pc.count_index], pc.max_count, pc.target_blocks,
                                          pc.max_groups_x);
    if (pc.key_range != 0u) {
        uint key_min = params.key_min;
        uint key_max = params.key_max;
        p.key_min = key_min;
        p.key_max = key_max;
        uint base = key_min & ~(kRadixSortBins - 1u);
        // No kept key (min > max) or one value: the first pass was all there was to do.
        uint span = key_max > base ? key_max - base : 0u;
        uint bits = span == 0u ? 0u : uint(findMSB(span)) + 1u;
        uint passes = (bits + kRadixSortDigitBits - 1u) / kRadixSortDigitBits;
        passes = clamp(passes, 1u, pc.num_passes);
        p.key_base = base;
        p.range_passes = passes;
        for (uint pass = 0u; pass < kRadixSortMaxPasses; ++pass) {
            bool runs = pass < passes;
            p.pass_blocks[pass].x = runs ? p.dispatch_x : 0u;
            p.pass_rows[pass].x = runs ? kRadixSortBins : 0u;
        }
        p.copy_blocks.x = passes % 2u == 1u ? p.dispatch_x : 0u;
    }
    params = p;
}
