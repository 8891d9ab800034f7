// Composite stage body shared by gaussian_composite.comp (RGBA32F colour, for readback) and
// gaussian_composite_rgba16f.comp (RGBA16F, the Filament overlay): the storage image format
// must be declared in GLSL (no shaderStorageImageWriteWithoutFormat), so each colour format
// is its own SPIR-V module that defines OPEN3D_COMPOSITE_COLOR_FORMAT and includes this.
//
// One workgroup per 16x16 tile, one invocation per pixel, each 32 invocations an 8x4 pixel
// block. A fixed grid of workgroups steals tiles from a global atomic counter until none is
// left, each claiming its next tile while it composites the current one. A tile's entries
// are its range of the tile-sorted entries, found beforehand by gaussian_tile_ranges.comp
// (depth order preserved inside a tile); its splats are loaded cooperatively into shared
// memory in batches of 256 and blended front to back with exactly the 3DGS rules
// (docs/DESIGN.md "Numerical rules", cpu/Composite.cpp). Each pixel block visits only the batch
// splats whose culling ellipse meets it (CompositeBlockMask), a list built per batch by one
// workgroup scan, and takes them sixteen at a time (then eight, then singly): a step's
// alphas first (independent loads and arithmetic), then the serial transmittance chain. The
// lists pay only together with the steps (docs/perf/h100.md "Composite").
#ifndef OPEN3D_GAUSSIAN_COMPOSITE_GLSL
#define OPEN3D_GAUSSIAN_COMPOSITE_GLSL

#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#include "GaussianSplatCompositeContract.h"
#include "gaussian_device_address.glsl"

layout(local_size_x = kCompositeWorkgroupSize) in;

// 0: no scene depth; the texture binding is never read (the recorder binds a placeholder).
layout(constant_id = kSpecSceneDepth) const uint kSceneDepth = 0u;
// kCompositeExpectedDepthBit | kCompositeMedianDepthBit: the depth images to write. A clear
// bit drops that image's accumulation from every blend (8-10% of the composite, docs/perf/).
layout(constant_id = kSpecCompositeDepth) const uint kDepthOutputs =
        kCompositeExpectedDepthBit | kCompositeMedianDepthBit;
const bool kExpectedDepth = (kDepthOutputs & kCompositeExpectedDepthBit) != 0u;
const bool kMedianDepth = (kDepthOutputs & kCompositeMedianDepthBit) != 0u;
const bool kSplatId = (kDepthOutputs & kCompositeSplatIdBit) != 0u;
// 1: the colour goes to color_buffer instead of out_color (RGBA32F batches, no image copy).
layout(constant_id = kSpecColorBuffer) const uint kColorToBuffer = 0u;

layout(push_constant, std430) uniform PushConstantsBlock {
    GaussianCompositePushConstants pc;
};

layout(std430, set = 0, binding = kCompositeEntryValuesBinding) readonly buffer ValuesBlock {
    uint entry_values[];  // splat index, front to back inside a tile
};
layout(std430, set = 0, binding = kCompositeStateBinding) coherent buffer StateBlock {
    GaussianCompositeState state;
    uvec2 tile_ranges[];  // [begin, end) of each tile's entries (gaussian_tile_ranges.comp)
};
layout(set = 0, binding = kCompositeColorBinding, OPEN3D_COMPOSITE_COLOR_FORMAT) writeonly
uniform image2D out_color;
layout(set = 0, binding = kCompositeDepthBinding, r32f) writeonly uniform image2D out_depth;
layout(set = 0, binding = kCompositeAlphaBinding, r32f) writeonly uniform image2D out_alpha;
layout(set = 0, binding = kCompositeMedianDepthBinding, r32f) writeonly
uniform image2D out_median_depth;
layout(set = 0, binding = kCompositeSceneDepthBinding) uniform texture2D scene_depth;
layout(std430, set = 0, binding = kCompositeColorBufferBinding) writeonly buffer ColorBufferBlock {
    vec4 color_buffer[];  // row-major W x H, the same floats the image would hold
};
layout(set = 0, binding = kCompositeSplatIdBinding, r32ui) writeonly uniform uimage2D out_splat_id;

// The batch in shared memory: 48 B per splat, 12 KiB (lavapipe allows 32 KiB).
shared vec4 s_center_depth_opacity[kCompositeBatchSize];
shared vec4 s_conic[kCompositeBatchSize];
shared vec4 s_color[kCompositeBatchSize];
shared uint s_splat_index[kCompositeBatchSize];  // written only for the ID image (kSplatId)
// Per pixel block, the batch slots whose splat may change the block (CompositeBlockMask), in
// depth order: a block's invocations visit only those, 8 KiB.
shared uint s_block_slots[kCompositeBlocks * kCompositeBatchSize];
// Per subgroup, its invocations' block bits summed into one 16-bit counter per block.
shared uvec4 s_subgroup_counts[kCompositeMaxSubgroups];
shared uint s_tile;
// Pixels of the current tile that need no more splats (outside the image or T-stopped).
shared uint s_done;

// View-space z of the scene at a pixel. The texture holds Filament's reversed-Z depth
// d = near / z_view (infinite far plane, cleared to 0), so z_view = near / d; d <= 0 (clear,
// nothing drawn) means no geometry: +inf, which no splat depth exceeds.
float SceneViewDepth(ivec2 pixel) {
    int y = pc.scene_depth_flip_y != 0u ? int(pc.height) - 1 - pixel.y : pixel.y;
    float d = texelFetch(scene_depth, ivec2(pixel.x, y), 0).r;
    return d > 0.0 ? pc.scene_near / d : uintBitsToFloat(0x7F800000u);
}

// What one pixel has accumulated so far.
struct PixelState {
    vec2 position;  // 3DGS evaluates pixel (x, y) at (x, y), not at (x + 0.5, y + 0.5)
    float scene_z;  // view z of the scene geometry; +inf where there is none
    float transmittance;
    vec3 color;
    float weighted_depth;  // sum(alpha_i T_i z_i)
    float weight;          // sum(alpha_i T_i): 1 - T without the cancellation of 1 - T
    float median_depth;
    bool median_found;
    float best_weight;  // the dominant splat's alpha T so far: a strictly larger one replaces it
    uint best_splat;    // kCompositeNoSplat until a splat blends
    bool done;  // T-stopped (or outside the image): no further splat changes the pixel
};

// The splat of batch slot j at the pixel: its alpha under exactly the reference's rules, or 0
// where the pixel skips it (behind the scene, outside the ellipse, alpha < 1/255).
float SplatAlpha(uint j, PixelState p) {
    vec4 cdo = s_center_depth_opacity[j];
    // Scene-depth test: a splat behind the opaque geometry is skipped.
    if (kSceneDepth != 0u && cdo.z > p.scene_z) return 0.0;
    // The 3DGS power -(a dx^2 + c dy^2) / 2 - b dx dy in base-2 units (s_conic holds the
    // conic times -log2(e) / 2, -log2(e), -log2(e) / 2): exp(power) = exp2(power2), and the
    // multiplications by -1/2 and log2(e) are done once per splat, not per pixel.
    vec4 conic = s_conic[j];
    vec2 d = cdo.xy - p.position;
    float power2 = d.x * (conic.x * d.x + conic.y * d.y) + conic.z * d.y * d.y;
    // conic.w = -t log2(e) / 2 for the splat's widened tile-culling threshold t
    // (TileCullThreshold): below it alpha < 1/255 is certain even after this float32
    // rounding of the power (its margin covers the base change's ulp), so the pixel skips the
    // splat as the alpha test would.
    bool outside = power2 > 0.0 || power2 < conic.w;
    float alpha = outside ? 0.0 : min(kCompositeMaxAlpha, cdo.w * exp2(power2));
    return alpha < kCompositeMinAlpha ? 0.0 : alpha;
}

// Blends batch slot j with its alpha (> 0, from SplatAlpha) into the pixel.
void BlendAlpha(uint j, float alpha, inout PixelState p) {
    float next_transmittance = p.transmittance * (1.0 - alpha);
    // Stop BEFORE blending: this splat would make the pixel (almost) opaque.
    if (next_transmittance < kCompositeMinTransmittance) {
        p.done = true;
        return;
    }
    float weight = alpha * p.transmittance;
    p.color += s_color[j].rgb * weight;
    if (kExpectedDepth || kMedianDepth) {
        float z = s_center_depth_opacity[j].z;
        if (kExpectedDepth) {
            p.weighted_depth += z * weight;
            p.weight += weight;
        }
        if (kMedianDepth && !p.median_found && 1.0 - next_transmittance >= 0.5) {
            p.median_depth = z;
            p.median_found = true;
        }
    }
    if (kSplatId && weight > p.best_weight) {
        p.best_weight = weight;
        p.best_splat = s_splat_index[j];
    }
    p.transmittance = next_transmittance;
}

void BlendSplat(uint j, inout PixelState p) {
    float alpha = SplatAlpha(j, p);
    if (alpha > 0.0) BlendAlpha(j, alpha, p);
}

const float kLog2E = 1.4426950408889634;

// Block mask bits as eight 16-bit counters, two per component, so that one vector scan
// counts every block at once (a batch holds at most 256 splats: no carry between fields).
uvec4 SpreadBlockBits(uint mask) {
    uvec4 spread = uvec4(0u);
    [[unroll]] for (uint k = 0u; k < kCompositeBlocks; ++k) {
        spread[k >> 1u] |= ((mask >> k) & 1u) << (16u * (k & 1u));
    }
    return spread;
}

uint BlockCounter(uvec4 counters, uint k) {
    return (counters[k >> 1u] >> (16u * (k & 1u))) & 0xFFFFu;
}

// Splats blended per step of the batch loop. Unrolled because llvmpipe (lavapipe) ends
// every loop of an invocation once 65535 back-edges have been taken in total (gallivm's loop
// limiter): with steps of 16 (at most 24 back-edges per batch of 256) a tile may hold ~700k
// entries. Steps of 16, then one of 8, measured fastest on NVIDIA; at 122 registers two
// workgroups still share an SM, and the unrolled loads are what hides the shared-memory and
// exp2 latency (docs/perf/h100.md "Composite").
const uint kUnroll = 16u;

// One step of N splats from position j of the block's list: N alphas, then N blends in order.
#define BLEND_STEP(N)                                                         \
    {                                                                         \
        uint slots[N];                                                        \
        float alphas[N];                                                      \
        [[unroll]] for (uint k = 0u; k < N; ++k) {                            \
            slots[k] = s_block_slots[list + j + k];                           \
            alphas[k] = SplatAlpha(slots[k], p);                              \
        }                                                                     \
        [[unroll]] for (uint k = 0u; k < N; ++k) {                            \
            if (!p.done && alphas[k] > 0.0) BlendAlpha(slots[k], alphas[k], p); \
        }                                                                     \
    }

// The entry range of a tile; past the last tile (a claim that found none left) empty.
uvec2 TileRange(uint tile, uint num_tiles) {
    // A tile the geometry stage's run bounds never reached holds (0xFFFFFFFF, 0): empty.
    uvec2 range = tile < num_tiles ? tile_ranges[tile] : uvec2(0u);
    return uvec2(min(range.x, range.y), range.y);
}

// The splat index of this invocation's entry in the first batch of `range`; 0 past its end.
uint FirstIndex(uvec2 range, uint slot) {
    return range.x + slot < range.y ? entry_values[range.x + slot] : 0u;
}

// Composites one tile from its entries [range.x, range.y). next_index is entry_values[range.x
// + slot] (0 past the range), read by the caller one tile ahead; the same read for
// `upcoming`, the range of the tile this workgroup takes next, is returned: it is issued after
// the blending, when that range has long arrived, and is waited for only at the next tile's
// first batch, so its latency overlaps this tile's stores and the next tile's set-up.
uint CompositeTile(uint tile, uvec2 range, uint next_index, uvec2 upcoming, uint slot,
                   uvec2 in_tile, uint block) {
    uint local = gl_LocalInvocationIndex;
    uvec2 size = uvec2(pc.width, pc.height);
    uint tiles_x = pc.tiles_x;
    uvec2 tile_origin = uvec2(tile % tiles_x, tile / tiles_x) * kCompositeTileSize;
    ivec2 pixel = ivec2(tile_origin + in_tile);
    bool inside = pixel.x < int(size.x) && pixel.y < int(size.y);
    uint begin = range.x;
    uint end = range.y;
    uint64_t projected = DeviceAddress(pc.projected_lo, pc.projected_hi);
    if (local == 0u) s_done = 0u;
    PixelState p;
    p.position = vec2(pixel);
    p.scene_z = uintBitsToFloat(0x7F800000u);
    if (kSceneDepth != 0u && inside) p.scene_z = SceneViewDepth(pixel);
    p.transmittance = 1.0;
    p.color = vec3(0.0);
    p.weighted_depth = 0.0;
    p.weight = 0.0;
    p.median_depth = 0.0;
    p.median_found = false;
    p.best_weight = 0.0;
    p.best_splat = kCompositeNoSplat;
    p.done = !inside;
    // s_done reset before the increments below. main() relies on this barrier too: every
    // invocation has read s_tile before it is written for the tile after the next.
    barrier();
    if (p.done) atomicAdd(s_done, 1u);

    // The splat index of this invocation's next batch entry is read one batch ahead, so a
    // batch load waits on one gather instead of two dependent ones. Reading the whole next
    // record ahead holds more registers across the blend loop and measured slower
    // (docs/perf/h100.md).
    for (uint batch = begin; batch < end; batch += kCompositeBatchSize) {
        barrier();  // the previous batch is consumed and its s_done increments made
        // Early exit when every pixel of the tile is done. Uniform: s_done is read
        // between two barriers, where no invocation changes it.
        if (s_done == kCompositeWorkgroupSize) break;
        uint entry = batch + slot;
        uint mask = 0u;
        if (entry < end) {
            GaussianProjectedSplat splat = LoadProjected(projected, next_index);
            if (kSplatId) s_splat_index[slot] = next_index;
            if (entry + kCompositeBatchSize < end) {
                next_index = entry_values[entry + kCompositeBatchSize];
            }
            s_center_depth_opacity[slot] =
                vec4(splat.center_x, splat.center_y, splat.depth, splat.opacity);
            s_conic[slot] = vec4(splat.conic, splat.cull_threshold) *
                            vec4(-0.5 * kLog2E, -kLog2E, -0.5 * kLog2E, -0.5 * kLog2E);
            s_color[slot] = vec4(splat.color, splat.det_q);
            mask = CompositeBlockMask(splat.center_x, splat.center_y, splat.conic.x,
                                      splat.conic.y, splat.conic.z, splat.det_q,
                                      splat.cull_threshold, float(tile_origin.x),
                                      float(tile_origin.y));
        }
        // Each block's list of the slots whose bit is set, in slot (depth) order: a
        // workgroup scan of the eight counters at once.
        uvec4 spread = SpreadBlockBits(mask);
        uvec4 inclusive = subgroupInclusiveAdd(spread);
        if (gl_SubgroupInvocationID == subgroupMax(gl_SubgroupInvocationID)) {
            s_subgroup_counts[gl_SubgroupID] = inclusive;
        }
        barrier();
        uvec4 before = uvec4(0u);
        uvec4 total = uvec4(0u);
        for (uint s = 0u; s < gl_NumSubgroups; ++s) {
            if (s == gl_SubgroupID) before = total;
            total += s_subgroup_counts[s];
        }
        uvec4 position = before + inclusive - spread;
        [[unroll]] for (uint k = 0u; k < kCompositeBlocks; ++k) {
            if (((mask >> k) & 1u) != 0u) {
                s_block_slots[k * kCompositeBatchSize + BlockCounter(position, k)] = slot;
            }
        }
        barrier();
        if (p.done) continue;
        uint count = BlockCounter(total, block);
        uint list = block * kCompositeBatchSize;
        uint j = 0u;
        // An alpha does not depend on the transmittance: a step's loads and exp2s overlap,
        // and only its blending is a serial chain. Steps of 16, one of 8, then one by one.
        for (; j + kUnroll <= count && !p.done; j += kUnroll) BLEND_STEP(kUnroll);
        if (j + kUnroll / 2u <= count && !p.done) {
            BLEND_STEP(kUnroll / 2u);
            j += kUnroll / 2u;
        }
        for (; j < count && !p.done; ++j) BlendSplat(s_block_slots[list + j], p);
        if (p.done) atomicAdd(s_done, 1u);  // once: done pixels skip later batches
    }
    uint upcoming_index = FirstIndex(upcoming, slot);

    if (inside) {
        float accumulated = 1.0 - p.transmittance;
        const vec4 color = vec4(p.color + p.transmittance * pc.background, accumulated);
        if (kColorToBuffer != 0u) {
            color_buffer[uint(pixel.y) * pc.width + uint(pixel.x)] = color;
        } else {
            imageStore(out_color, pixel, color);
        }
        if (kExpectedDepth) {
            imageStore(out_depth, pixel,
                       vec4(p.weight > 0.0 ? p.weighted_depth / p.weight : 0.0));
            imageStore(out_alpha, pixel, vec4(accumulated));
        }
        if (kMedianDepth) imageStore(out_median_depth, pixel, vec4(p.median_depth));
        if (kSplatId) imageStore(out_splat_id, pixel, uvec4(p.best_splat));
    }
    return upcoming_index;
}

void main() {
    uint local = gl_LocalInvocationIndex;
    uint num_tiles = pc.tiles_x * pc.tiles_y;
    // Workgroup i starts with tile i, then steals tiles num_workgroups, num_workgroups + 1...
    // from the counter: with as many workgroups as tiles (CPU devices) each does one tile.
    uint tile = gl_WorkGroupID.x;
    // This invocation's pixel within every tile it takes. Invocations 32 k .. 32 k + 31
    // cover block k of the tile: 8 columns by 4 rows, two blocks side by side. A compact block
    // meets fewer splats than a 16x2 row pair and its pixels agree more often on whether they
    // blend a splat, which is what a subgroup of 32 pays for (docs/perf/h100.md "Composite").
    uint block = local / (kCompositeBlockWidth * kCompositeBlockHeight);
    uint blocks_x = kCompositeTileSize / kCompositeBlockWidth;
    uvec2 in_tile = uvec2(
            (block % blocks_x) * kCompositeBlockWidth + local % kCompositeBlockWidth,
            (block / blocks_x) * kCompositeBlockHeight +
                    (local / kCompositeBlockWidth) % kCompositeBlockHeight);

    // The batch is loaded in scan order (subgroups by gl_SubgroupID, lanes by
    // gl_SubgroupInvocationID) so that the block lists below, built by subgroup scans, keep
    // the depth order; gl_LocalInvocationIndex need not follow that order, so it is counted.
    uint subgroup_lanes = subgroupAdd(1u);
    if (subgroupElect()) s_subgroup_counts[gl_SubgroupID].x = subgroup_lanes;
    barrier();
    uint slot = subgroupExclusiveAdd(1u);
    for (uint s = 0u; s < gl_SubgroupID; ++s) slot += s_subgroup_counts[s].x;

    // Tiles are claimed one ahead (near the end, see below): while a workgroup composites a
    // tile, the tile after it is already in s_tile and its range in flight, and the claim of
    // the one after that is in flight too. Claiming, reading the range and then the first
    // index between two tiles waits on three dependent global accesses per tile, which
    // counts most where tiles are many and short (4K; docs/perf/h200.md).
    uvec2 range = TileRange(tile, num_tiles);
    uint next_index = FirstIndex(range, slot);
    if (local == 0u) s_tile = gl_NumWorkGroups.x + atomicAdd(state.next_tile, 1u);
    barrier();
    while (tile < num_tiles) {  // uniform: tile comes from shared memory after a barrier
        uint following = s_tile;
        uvec2 following_range = TileRange(following, num_tiles);
        uint claimed = 0u;
        // Near the end of the tiles, a tile claimed ahead waits for the current one while
        // other workgroups find none left: in the last 2 x num_workgroups tiles the claim is
        // made after the tile (docs/perf/h200.md). CPU devices always claim after.
        bool ahead = following + 2u * gl_NumWorkGroups.x < num_tiles;
        if (ahead && local == 0u) claimed = atomicAdd(state.next_tile, 1u);
        next_index = CompositeTile(tile, range, next_index, following_range, slot, in_tile,
                                   block);
        if (!ahead && local == 0u) claimed = atomicAdd(state.next_tile, 1u);
        // Publish the claim (every invocation read s_tile before CompositeTile's first
        // barrier). The barrier also makes sure every invocation has read s_done before the
        // next tile resets it.
        if (local == 0u) s_tile = gl_NumWorkGroups.x + claimed;
        barrier();
        tile = following;
        range = following_range;
    }
}

#endif  // OPEN3D_GAUSSIAN_COMPOSITE_GLSL
