// The composite's part of the GPU contract (GaussianCompositeStage.cpp,
// shaders/gaussian_tile_ranges.comp, gaussian_composite*.comp, gaussian_depth_merge.comp):
// workgroup and pixel-block sizes, the blending thresholds, the per-block culling mask,
// bindings, the work-stealing state and the push constants of the composite and the depth
// merge. A stage of its own because it reads only the projected splats and the sorted tile
// entries: the geometry stage's other layouts can change without touching it.
// GLSL and C++ as GaussianSplatCommon.h says; C++ gets static_asserts on every offset.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_COMPOSITE_CONTRACT_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_COMPOSITE_CONTRACT_H

#include "GaussianSplatProjectionContract.h"

#ifdef __cplusplus
namespace open3d {
namespace visualization {
namespace rendering {
namespace shader {
#endif

// One composite workgroup per 16x16 tile, one invocation per pixel; the tile's splats are
// loaded into shared memory in batches of one splat per invocation (48 B each: 12 KiB).
OPEN3D_SHADER_CONST uint kCompositeTileSize = 16u;  // == kGaussianTileSize (asserted in C++)
OPEN3D_SHADER_CONST uint kCompositeWorkgroupSize = 256u;
OPEN3D_SHADER_CONST uint kCompositeBatchSize = 256u;
// Each 32 invocations blend an 8x4 pixel block of the tile (gaussian_composite.glsl).
OPEN3D_SHADER_CONST uint kCompositeBlockWidth = 8u;
OPEN3D_SHADER_CONST uint kCompositeBlockHeight = 4u;
// Pixel blocks of a tile, numbered row-major: block k covers columns
// (k % kCompositeBlocksX) * kCompositeBlockWidth.. and rows (k / kCompositeBlocksX) *
// kCompositeBlockHeight.. of the tile (one bit each in CompositeBlockMask).
OPEN3D_SHADER_CONST uint kCompositeBlocksX = kCompositeTileSize / kCompositeBlockWidth;
OPEN3D_SHADER_CONST uint kCompositeBlocksY = kCompositeTileSize / kCompositeBlockHeight;
OPEN3D_SHADER_CONST uint kCompositeBlocks = kCompositeBlocksX * kCompositeBlocksY;
// Bound of gl_NumSubgroups in a composite workgroup: subgroups of at least 8 invocations,
// which RadixSort already requires of the device.
OPEN3D_SHADER_CONST uint kCompositeMaxSubgroups = kCompositeWorkgroupSize / 8u;
// The depth merge runs 16x16 pixels per workgroup.
OPEN3D_SHADER_CONST uint kDepthMergeWorkgroupSize = 16u;
// So does the blend over the mesh colour.
OPEN3D_SHADER_CONST uint kBlendOverWorkgroupSize = 16u;

// The 3DGS blending thresholds as float32 (docs/DESIGN.md section 3; == cpu::kMaxAlpha etc.).
OPEN3D_SHADER_CONST float kCompositeMaxAlpha = 0.99f;
OPEN3D_SHADER_CONST float kCompositeMinAlpha = 1.0f / 255.0f;
OPEN3D_SHADER_CONST float kCompositeMinTransmittance = 0.0001f;

// Specialisation constant of gaussian_composite*.comp and gaussian_depth_merge.comp:
// 1 = a scene depth texture is bound and tested; 0 = it is never read.
OPEN3D_SHADER_CONST uint kSpecSceneDepth = 0u;
// Specialisation constant of gaussian_composite*.comp: which images beside the colour it
// writes, a sum of the bits below (0 = colour only). Each bit drops per-blend arithmetic when
// clear.
OPEN3D_SHADER_CONST uint kSpecCompositeDepth = 1u;
OPEN3D_SHADER_CONST uint kCompositeExpectedDepthBit = 1u;  // expected depth and alpha images
OPEN3D_SHADER_CONST uint kCompositeMedianDepthBit = 2u;    // median depth image
OPEN3D_SHADER_CONST uint kCompositeSplatIdBit = 4u;        // ID image of the dominant splat
// The ID image's value where no splat blends (-1 read as int32).
OPEN3D_SHADER_CONST uint kCompositeNoSplat = 0xFFFFFFFFu;
// Specialisation constant of gaussian_composite.comp (RGBA32F): 1 = the colour goes to the
// storage buffer at kCompositeColorBufferBinding (vec4 per pixel, row-major) instead of the
// image, so a batch's views need no image-to-buffer copy (0.18 ms per 800x800 view on an
// H200, docs/perf/h200.md); 0 = the image.
OPEN3D_SHADER_CONST uint kSpecColorBuffer = 2u;

// Which pixel blocks of a tile a splat can change: bit k is set unless no pixel of block k
// lies in the splat's culling ellipse q <= t (TileCullThreshold, stored as cull_threshold), found
// per row of blocks with EllipseBandReach as TileRowSpan finds tiles, so a block with a clear
// bit receives only skips, exactly as a culled tile. (x0, y0) is the tile's first pixel,
// (cx, cy) the splat centre; pixel (x, y) is evaluated at (x, y). Nothing finite to bound by
// (a degenerate conic, NaN): every block.
OPEN3D_SHADER_FUNC uint CompositeBlockMask(float cx, float cy, float a, float b, float c,
                                           float det_q, float t, float x0, float y0) {
    uint all = (1u << kCompositeBlocks) - 1u;
    uint row = (1u << kCompositeBlocksX) - 1u;
    if (!(t > 0.0f)) return 0u;
    OPEN3D_SHADER_PRECISE float x_ext = sqrt(c * t / det_q);
    OPEN3D_SHADER_PRECISE float y_ext = sqrt(a * t / det_q);
    if (!(x_ext < 1e30f && y_ext < 1e30f && a > 0.0f && c > 0.0f)) return all;
    uint mask = 0u;
    for (uint by = 0u; by < kCompositeBlocksY; ++by) {
        OPEN3D_SHADER_PRECISE float lo = y0 + float(by * kCompositeBlockHeight) - cy;
        OPEN3D_SHADER_PRECISE float hi = lo + float(kCompositeBlockHeight - 1u);
        vec4 band = EllipseBandReach(a, b, c, det_q, t, x_ext, y_ext, lo, hi);
        if (band.w == 0.0f) continue;
        OPEN3D_SHADER_PRECISE float left = cx + band.x - band.z - x0;
        OPEN3D_SHADER_PRECISE float right = cx + band.y + band.z - x0;
        uint columns = 0u;
        for (uint bx = 0u; bx < kCompositeBlocksX; ++bx) {
            float first = float(bx * kCompositeBlockWidth);
            if (right >= first && left <= first + float(kCompositeBlockWidth - 1u)) {
                columns |= 1u << bx;
            }
        }
        if (!(left <= right)) columns = row;  // NaN
        mask |= columns << (by * kCompositeBlocksX);
    }
    return mask;
}

// Descriptor set 0 of the composite (push descriptors). The projected records are read
// through their device address (GaussianCompositePushConstants::projected_lo / _hi).
OPEN3D_SHADER_CONST uint kCompositeEntryKeysBinding = 0u;    // uint[capacity]: tile, ascending
OPEN3D_SHADER_CONST uint kCompositeEntryValuesBinding = 1u;  // uint[capacity]: splat index
OPEN3D_SHADER_CONST uint kCompositeCountBinding = 2u;        // uint[]: entry count at count_index
OPEN3D_SHADER_CONST uint kCompositeStateBinding = 3u;        // GaussianCompositeState
OPEN3D_SHADER_CONST uint kCompositeColorBinding = 4u;        // image2D rgba32f / rgba16f
OPEN3D_SHADER_CONST uint kCompositeDepthBinding = 5u;        // image2D r32f: expected view z
OPEN3D_SHADER_CONST uint kCompositeAlphaBinding = 6u;        // image2D r32f: 1 - T
OPEN3D_SHADER_CONST uint kCompositeMedianDepthBinding = 7u;  // image2D r32f: median view z
OPEN3D_SHADER_CONST uint kCompositeSceneDepthBinding = 8u;   // texture2D, reversed-Z
OPEN3D_SHADER_CONST uint kCompositeColorBufferBinding = 9u;  // vec4[W * H] (kSpecColorBuffer)
OPEN3D_SHADER_CONST uint kCompositeSplatIdBinding = 10u;     // uimage2D r32ui: dominant splat
OPEN3D_SHADER_CONST uint kCompositeNumBindings = 11u;

// Descriptor set 0 of the depth merge (push descriptors).
OPEN3D_SHADER_CONST uint kDepthMergeSplatDepthBinding = 0u;  // image2D r32f: splat view z
OPEN3D_SHADER_CONST uint kDepthMergeSplatAlphaBinding = 1u;  // image2D r32f: splat 1 - T
OPEN3D_SHADER_CONST uint kDepthMergeSceneDepthBinding = 2u;  // texture2D, reversed-Z
OPEN3D_SHADER_CONST uint kDepthMergeNormalizedBinding = 3u;  // uimage2D r16ui
OPEN3D_SHADER_CONST uint kDepthMergeLinearBinding = 4u;      // image2D r32f: merged view z
OPEN3D_SHADER_CONST uint kDepthMergeNumBindings = 5u;

// Descriptor set 0 of the blend over the mesh colour (push descriptors).
OPEN3D_SHADER_CONST uint kBlendOverSplatColorBinding = 0u;  // image2D rgba16f: premultiplied
OPEN3D_SHADER_CONST uint kBlendOverMeshColorBinding = 1u;   // texture2D: RGBA8 unorm mesh colour
OPEN3D_SHADER_CONST uint kBlendOverOutputBinding = 2u;      // uint[W * H]: RGBA8, top row first
OPEN3D_SHADER_CONST uint kBlendOverNumBindings = 3u;

// Work-stealing state of one composite dispatch (std430): zeroed by the recorder
// (vkCmdFillBuffer) before every dispatch; each workgroup claims tiles with atomicAdd.
struct GaussianCompositeState {
    uint next_tile;
    uint reserved0;
    uint reserved1;
    uint reserved2;
};

// Push constants of the composite.
struct GaussianCompositePushConstants {
    uint width, height, tiles_x, tiles_y;
    uint count_index;         // uint index of the entry count in the count binding
    uint entry_capacity;      // entries allocated
    uint scene_depth_flip_y;  // 1: the scene depth's row 0 is the bottom row (GL)
    uint reserved0;
    vec3 background;   // out.rgb = C + T * background
    float scene_near;  // near of the reversed-Z scene depth (view z = near / d)
    // Device address of the GaussianProjectedSplat records (low, high words).
    uint projected_lo, projected_hi;
    uint reserved1, reserved2;
};

// Push constants of the depth merge.
struct GaussianDepthMergePushConstants {
    uint width, height;
    uint scene_depth_flip_y;  // as in GaussianCompositePushConstants
    uint reserved0;
    float near_plane, far_plane;  // range of the normalisation
    float scene_near;             // as in GaussianCompositePushConstants
    float min_alpha;              // min splat alpha for the splat depth to count
};

// Push constants of the blend over the mesh colour.
struct GaussianBlendOverPushConstants {
    uint width, height;
    uint mesh_flip_y;  // 1: the mesh colour's row 0 is the bottom row (GL)
    uint reserved0;
};

#ifdef __cplusplus
static_assert(kCompositeTileSize == kGaussianTileSize);
static_assert(kCompositeTileSize % kCompositeBlockWidth == 0u);
static_assert(kCompositeTileSize % kCompositeBlockHeight == 0u);
static_assert(kCompositeWorkgroupSize == kCompositeTileSize * kCompositeTileSize);
static_assert(kCompositeBatchSize == kCompositeWorkgroupSize, "one splat load per invocation");
static_assert(kCompositeBlocks <= 8u, "CompositeBlockMask's bits are counted in 16-bit fields");
static_assert(kCompositeBlocks * kCompositeBlockWidth * kCompositeBlockHeight ==
              kCompositeWorkgroupSize);

static_assert(sizeof(GaussianCompositeState) == 16);
static_assert(offsetof(GaussianCompositeState, next_tile) == 0);

static_assert(sizeof(GaussianCompositePushConstants) == 64);
static_assert(offsetof(GaussianCompositePushConstants, width) == 0);
static_assert(offsetof(GaussianCompositePushConstants, height) == 4);
static_assert(offsetof(GaussianCompositePushConstants, tiles_x) == 8);
static_assert(offsetof(GaussianCompositePushConstants, tiles_y) == 12);
static_assert(offsetof(GaussianCompositePushConstants, count_index) == 16);
static_assert(offsetof(GaussianCompositePushConstants, entry_capacity) == 20);
static_assert(offsetof(GaussianCompositePushConstants, scene_depth_flip_y) == 24);
static_assert(offsetof(GaussianCompositePushConstants, background) == 32);
static_assert(offsetof(GaussianCompositePushConstants, scene_near) == 44);
static_assert(offsetof(GaussianCompositePushConstants, projected_lo) == 48);

static_assert(sizeof(GaussianDepthMergePushConstants) == 32);
static_assert(offsetof(GaussianDepthMergePushConstants, width) == 0);
static_assert(offsetof(GaussianDepthMergePushConstants, height) == 4);
static_assert(offsetof(GaussianDepthMergePushConstants, scene_depth_flip_y) == 8);
static_assert(offsetof(GaussianDepthMergePushConstants, near_plane) == 16);
static_assert(offsetof(GaussianDepthMergePushConstants, far_plane) == 20);
static_assert(offsetof(GaussianDepthMergePushConstants, scene_near) == 24);
static_assert(offsetof(GaussianDepthMergePushConstants, min_alpha) == 28);

static_assert(sizeof(GaussianBlendOverPushConstants) == 16);
static_assert(offsetof(GaussianBlendOverPushConstants, width) == 0);
static_assert(offsetof(GaussianBlendOverPushConstants, height) == 4);
static_assert(offsetof(GaussianBlendOverPushConstants, mesh_flip_y) == 8);

}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_COMPOSITE_CONTRACT_H
