#version 460
// Writes every member of the contract's structs by name, with the value the C++ test
// expects at that member's C++ offset: a layout mismatch between std430 and the
// static_asserted C++ structs shows up as a wrong value. The push-constant structs are
// written into storage buffers, whose std430 layout is the push constants' one.
#extension GL_GOOGLE_include_directive : require
#include "GaussianSplatCompositeContract.h"
#include "GaussianSplatRadixSortContract.h"
#include "GaussianSplatTileListContract.h"

layout(local_size_x = 1) in;

layout(push_constant, std430) uniform PushConstantsBlock {
    RadixSortPushConstants pc;
};
layout(std430, set = 0, binding = 0) writeonly buffer ParamsOut {
    RadixSortParams params_out;
};
layout(std430, set = 0, binding = 1) writeonly buffer PushOut {
    RadixSortPushConstants push_out;
};
layout(std430, set = 0, binding = 2) writeonly buffer ViewOut {
    GaussianViewParams view_out;
};
layout(std430, set = 0, binding = 3) writeonly buffer SplatOut {
    GaussianProjectedSplat splat_out;
};
layout(std430, set = 0, binding = 4) writeonly buffer CompositeOut {
    GaussianCompositePushConstants composite_out;
};
layout(std430, set = 0, binding = 5) writeonly buffer DepthMergeOut {
    GaussianDepthMergePushConstants merge_out;
};

// The named members of the stage structs, numbered in declaration order from 300 (floats as
// that number): the C++ test checks each at its own offset.
void WriteStageStructs() {
    view_out.rotation_row0 = vec3(300.0, 301.0, 302.0);
    view_out.center_low_x = 303.0;
    view_out.rotation_row1 = vec3(304.0, 305.0, 306.0);
    view_out.center_low_y = 307.0;
    view_out.rotation_row2 = vec3(308.0, 309.0, 310.0);
    view_out.center_low_z = 311.0;
    view_out.center_high = vec3(312.0, 313.0, 314.0);
    view_out.reserved0 = 315.0;
    view_out.fx = 316.0;
    view_out.fy = 317.0;
    view_out.cx = 318.0;
    view_out.cy = 319.0;
    view_out.guard_x = 320.0;
    view_out.guard_y = 321.0;
    view_out.near_plane = 322.0;
    view_out.packed_depth_scale = 323.0;
    view_out.width = 324u;
    view_out.height = 325u;
    view_out.tiles_x = 326u;
    view_out.tiles_y = 327u;
    view_out.entry_capacity = 328u;
    view_out.max_tiles_per_splat = 329u;
    view_out.max_tile_entries_total = 330u;
    view_out.tile_bits = 331u;
    view_out.num_splats = 332u;
    view_out.sh_degree = 333u;
    view_out.antialias = 334u;
    view_out.sh_words_per_splat = 335u;
    view_out.scene_depth_present = 336u;
    view_out.splat_precision = 337u;
    view_out.shape_words_per_splat = 338u;
    view_out.entry_capacity_allocated = 339u;
    view_out.reference_m2 = 340.0;
    view_out.reference_m6 = 341.0;
    view_out.reference_m10 = 342.0;
    view_out.reference_m14 = 343.0;
    view_out.depth_order = 344u;
    view_out.lod_budget = 345u;
    view_out.guard_center_x = 346.0;
    view_out.guard_center_y = 347.0;

    splat_out.center_x = 400.0;
    splat_out.center_y = 401.0;
    splat_out.depth = 402.0;
    splat_out.opacity = 403.0;
    splat_out.conic = vec3(404.0, 405.0, 406.0);
    splat_out.cull_threshold = 407.0;
    splat_out.color = vec3(408.0, 409.0, 410.0);
    splat_out.det_q = 411.0;
    splat_out.rect_min = 412u;
    splat_out.rect_max = 413u;
    splat_out.num_entries = 414u;
    splat_out.radius = 415u;

    composite_out.width = 500u;
    composite_out.height = 501u;
    composite_out.tiles_x = 502u;
    composite_out.tiles_y = 503u;
    composite_out.count_index = 504u;
    composite_out.entry_capacity = 505u;
    composite_out.scene_depth_flip_y = 506u;
    composite_out.reserved0 = 507u;
    composite_out.background = vec3(508.0, 509.0, 510.0);
    composite_out.scene_near = 511.0;

    merge_out.width = 600u;
    merge_out.height = 601u;
    merge_out.scene_depth_flip_y = 602u;
    merge_out.reserved0 = 603u;
    merge_out.near_plane = 604.0;
    merge_out.far_plane = 605.0;
    merge_out.scene_near = 606.0;
    merge_out.min_alpha = 607.0;
}

void main() {
    params_out.dispatch_x = 101u;
    params_out.dispatch_y = 102u;
    params_out.dispatch_z = 103u;
    params_out.count = 104u;
    params_out.num_blocks = 105u;
    params_out.flags = 106u;
    params_out.block_size = 107u;
    params_out.key_base = 108u;
    params_out.key_min = 114u;
    params_out.key_max = 115u;
    params_out.range_passes = 109u;
    for (uint pass = 0u; pass < kRadixSortMaxPasses; ++pass) {
        params_out.pass_blocks[pass] = uvec4(110u, 111u, 112u, 113u) + 10u * pass;
        params_out.pass_rows[pass] = uvec4(150u, 151u, 152u, 153u) + 10u * pass;
    }
    params_out.copy_blocks = uvec4(190u, 191u, 192u, 193u);
    params_out.sweep_histogram_grid = uvec4(194u, 195u, 196u, 197u);
    // Push constants read by member name, written back member by member.
    push_out.shift = pc.shift;
    push_out.digit_bits = pc.digit_bits;
    push_out.count_index = pc.count_index;
    push_out.max_count = pc.max_count;
    push_out.target_blocks = pc.target_blocks;
    push_out.drop_max_keys = pc.drop_max_keys;
    push_out.key_range = pc.key_range;
    push_out.num_passes = pc.num_passes;
    push_out.values_only = pc.values_only;
    push_out.max_groups_x = pc.max_groups_x;
    push_out.num_bits = pc.num_bits;
    push_out.sweep = pc.sweep;
    push_out.run_keys = pc.run_keys;
    push_out.run_offset = pc.run_offset;
    WriteStageStructs();
}
