// Shared by the radix-sort shaders: bindings, push constants and workgroup-wide scans that
// are correct for any subgroup size and shape (8 on lavapipe, 32 NVIDIA/Apple, 64 AMD).
#ifndef OPEN3D_RADIX_SORT_COMMON_GLSL
#define OPEN3D_RADIX_SORT_COMMON_GLSL

#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require

#include "GaussianSplatRadixSortContract.h"

layout(push_constant, std430) uniform PushConstantsBlock {
    RadixSortPushConstants pc;
};

// RadixSortParams::key_base of this sort; the histogram and scatter set it from params.
uint g_key_base = 0u;

uint DigitOf(uint key) {
    return ((key - g_key_base) >> pc.shift) & ((1u << pc.digit_bits) - 1u);
}

// Whether this pass writes keys: all but the last pass that runs (`passes_run` of them) of
// a values-only sort.
bool WritesKeys(uint passes_run) {
    return pc.values_only == 0u || pc.shift / kRadixSortDigitBits + 1u < passes_run;
}

// Whether a pair in the input takes part in this pass: all of them but the dropped keys of
// a first pass with drop_max_keys (RadixSort::DropMaxKeys).
bool IsKept(uint key) {
    return pc.drop_max_keys == 0u || key != kRadixSortDroppedKey;
}

layout(constant_id = kSpecRadixSortSubgroups) const uint kMaxSubgroups = kRadixSortMaxSubgroups;

// Per-subgroup partial sums, indexed by gl_SubgroupID.
shared uint s_subgroup_sum[kMaxSubgroups];

// The position of this invocation in the workgroup's scan order: subgroups in
// gl_SubgroupID order, lanes in gl_SubgroupInvocationID order (the order of the subgroup
// scans). Elements are loaded by this slot so that scan order equals element order, which
// is what makes the sort stable; gl_LocalInvocationIndex need not follow that order and
// subgroups may be partial, so the slot is counted, not computed.
uint g_slot;
// This invocation's subgroup: its active lanes and the slot of its first one.
uint g_subgroup_lanes;
uint g_subgroup_first_slot;

void InitScanSlot() {
    g_subgroup_lanes = subgroupAdd(1u);
    if (subgroupElect()) s_subgroup_sum[gl_SubgroupID] = g_subgroup_lanes;
    barrier();
    g_subgroup_first_slot = 0u;
    for (uint s = 0u; s < gl_SubgroupID; ++s) g_subgroup_first_slot += s_subgroup_sum[s];
    g_slot = g_subgroup_first_slot + subgroupExclusiveAdd(1u);
    barrier();
}

// Exclusive prefix sum of `value` over the workgroup in slot order; `total` gets the sum.
uint WorkgroupExclusiveAdd(uint value, out uint total) {
    uint inclusive_in_subgroup = subgroupInclusiveAdd(value);
    if (gl_SubgroupInvocationID == subgroupMax(gl_SubgroupInvocationID)) {
        s_subgroup_sum[gl_SubgroupID] = inclusive_in_subgroup;
    }
    barrier();
    uint prefix = 0u;
    uint sum = 0u;
    for (uint s = 0u; s < gl_NumSubgroups; ++s) {
        if (s == gl_SubgroupID) prefix = sum;
        sum += s_subgroup_sum[s];
    }
    barrier();  // s_subgroup_sum is reused by the next scan
    total = sum;
    return prefix + inclusive_in_subgroup - value;
}

#endif  // OPEN3D_RADIX_SORT_COMMON_GLSL
