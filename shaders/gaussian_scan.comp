#version 460
// Geometry stage, exclusive prefix sum of the per-splat tile counts in depth order, one level of
// a block hierarchy (kScanBlockSize counts per workgroup): exclusive offsets within the
// block in place and the block's total one level up. There is no down-sweep: readers add
// the levels above (ScanOffset in gaussian_scan_offset.glsl). Additions saturate at
// kScanSaturation (the total of a frame can pass 2^32), and the workgroup scan runs in
// shared memory by local index, so the result does not depend on the subgroup size or
// shape. Level 0 with kScanGather reads its counts from the depth-sorted visible list
// (splats over max_tiles_per_splat count 0 and flag; slots past visible_count, which the
// exact order also scans, count 0).
#extension GL_GOOGLE_include_directive : require
#include "GaussianSplatTileListContract.h"

layout(local_size_x = kScanWorkgroupSize) in;

layout(constant_id = kSpecScanGather) const uint kGather = 0u;

layout(push_constant, std430) uniform PushConstantsBlock {
    GaussianScanPushConstants pc;
};

layout(std430, set = 0, binding = kGeometryStageViewBinding) readonly buffer ViewBlock {
    GaussianViewParams view;
};
layout(std430, set = 0, binding = kGeometryStageTileCountsBinding) readonly buffer TileCountsBlock {
    uint tile_counts[];  // by splat index, written by the projection for visible splats
};
layout(std430, set = 0, binding = kGeometryStageCountersBinding) buffer CountersBlock {
    GaussianGeometryStageCounters counters;
};
layout(std430, set = 0, binding = kGeometryStageSplatIndexBinding) readonly buffer SplatIndexBlock {
    uint splat_indices[];
};
layout(std430, set = 0, binding = kGeometryStageScanBinding) buffer ScanBlock {
    uint scan[];
};

#include "gaussian_scan_offset.glsl"
#include "gaussian_list_count.glsl"

shared uint s_sums[kScanWorkgroupSize];

uint LoadCount(uint index) {
    return kGather == 0u ? scan[pc.base + index] : ListSlotTileCount(index);
}

void ScanBlockPass(uint count) {
    uint block = FlatWorkGroupIndex();
    // A spare workgroup of the grid's last row (a block past the count) has nothing to add
    // and must not store a block sum.
    if (block > 0u && block * kScanBlockSize >= count) return;
    uint local = gl_LocalInvocationIndex;
    uint first = block * kScanBlockSize + local * kScanItemsPerInvocation;
    uint values[kScanItemsPerInvocation];
    uint sum = 0u;
    for (uint k = 0u; k < kScanItemsPerInvocation; ++k) {
        uint index = first + k;
        uint value = index < count ? LoadCount(index) : 0u;
        values[k] = sum;  // exclusive within this invocation
        sum = SatAdd(sum, value);
    }
    // Hillis-Steele inclusive scan of the invocation sums, in local-index order.
    s_sums[local] = sum;
    barrier();
    for (uint offset = 1u; offset < kScanWorkgroupSize; offset <<= 1u) {
        uint other = local >= offset ? s_sums[local - offset] : 0u;
        barrier();
        s_sums[local] = SatAdd(s_sums[local], other);
        barrier();
    }
    uint prefix = local > 0u ? s_sums[local - 1u] : 0u;
    for (uint k = 0u; k < kScanItemsPerInvocation; ++k) {
        uint index = first + k;
        if (index < count) scan[pc.base + index] = SatAdd(prefix, values[k]);
    }
    if (local == kScanWorkgroupSize - 1u) {
        uint block_total = s_sums[local];
        if (pc.write_total != 0u) {
            counters.requested_entries = block_total;
        } else {
            scan[pc.sums_base + block] = block_total;
        }
    }
}

void main() {
    ScanBlockPass(counters.scan_levels[pc.level].count);
}
