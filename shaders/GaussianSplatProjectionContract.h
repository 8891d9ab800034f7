// The projection's part of the GPU contract (GaussianGeometryStage.cpp,
// GaussianSplatDataPacking.cpp, shaders/gaussian_project.comp): the per-frame view
// parameters, the projected splat record the later passes read, the geometry stage's
// bindings and the projection's specialisation constants. A stage of its own because the
// view parameters are the one struct the host fills per frame: every value is a named member.
// GLSL and C++ as GaussianSplatCommon.h says; C++ gets static_asserts on every offset.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_PROJECTION_CONTRACT_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_PROJECTION_CONTRACT_H

#include "GaussianSplatCommon.h"

#ifdef __cplusplus
namespace open3d {
namespace visualization {
namespace rendering {
namespace shader {
#endif

// Workgroup size of the projection (one invocation per splat).
OPEN3D_SHADER_CONST uint kProjectWorkgroupSize = 256u;

// The depth that orders splats and culls at the near plane (RenderConfig::depth_order,
// GaussianSplatShared.h): the original rasterizer's float32 view z, or the camera-relative one.
OPEN3D_SHADER_CONST uint kDepthOrderReference = 0u;
OPEN3D_SHADER_CONST uint kDepthOrderCameraRelative = 1u;

// Precision of the packed attributes (specialisation constant kSpecPrecision).
OPEN3D_SHADER_CONST uint kPrecisionExact = 0u;    // fp32 everything
OPEN3D_SHADER_CONST uint kPrecisionCompact = 1u;  // fp16 scale, rotation, f_dc, SH
// uint words per splat in the shape buffer: scale xyz, rotation wxyz, f_dc rgb.
OPEN3D_SHADER_CONST uint kShapeWordsExact = 10u;   // 10 floats
OPEN3D_SHADER_CONST uint kShapeWordsCompact = 5u;  // 10 halves

// Specialisation constant ids of gaussian_project.comp.
OPEN3D_SHADER_CONST uint kSpecShDegree = 0u;   // 0..3; 0 reads no SH buffer
OPEN3D_SHADER_CONST uint kSpecAntialias = 1u;  // 0 / 1
OPEN3D_SHADER_CONST uint kSpecPrecision = 2u;  // kPrecisionExact / kPrecisionCompact
// 1 (exact order): slot i of the visible list holds splat i (key ~0u when not visible), so
// one stable depth sort of all N slots orders ties by splat index; 0 (packed key): visible
// splats are appended in subgroup order.
OPEN3D_SHADER_CONST uint kSpecIndexedList = 3u;
// 1 (a level-of-detail hierarchy's nodes): the visibility binding holds the cut's list of
// nodes (GaussianSplatLodContract.h) and slot i projects node list[i] when i is below
// GaussianGeometryStageCounters::lod_cut_nodes; 0: slot i projects splat i if its bit is set.
OPEN3D_SHADER_CONST uint kSpecCutList = 4u;
// 1 (per-tile bins, SortMode::kExact): a visible splat also adds 1 to the count of every
// tile it will emit into, in the tile ranges binding (GaussianSplatTileListContract.h).
OPEN3D_SHADER_CONST uint kSpecBinTiles = 5u;
// 1 (the exact order where the sorts run the one sweep, with the chained emit): the
// projection also adds the digits of every visible depth key to the depth sort's one-sweep
// histogram and zeroes its first pass's status rows, in place of the sort's histogram
// dispatch (RadixSortScratch::sweep_histogram_written).
OPEN3D_SHADER_CONST uint kSpecDepthDigits = 6u;

// Descriptor set 0 of every geometry stage projection pipeline (one push-descriptor layout; each
// shader declares only the bindings it uses). The positions, the shape and SH words and the
// projected records are not bound: they are read through device addresses
// (GaussianGeometryAddresses). What is bound takes at most 4 bytes a splat or entry, within one
// binding up to the sort's own limit (RadixSort::MaxCountFor).
OPEN3D_SHADER_CONST uint kGeometryStageViewBinding = 0u;  // GaussianViewParams
// uint[ceil(N / 32)], bit i = splat i; with kSpecCutList, uint[N]: the cut's nodes.
OPEN3D_SHADER_CONST uint kGeometryStageVisibilityBinding = 1u;
OPEN3D_SHADER_CONST uint kGeometryStageCountersBinding = 2u;     // GaussianGeometryStageCounters
OPEN3D_SHADER_CONST uint kGeometryStageDepthKeysBinding = 3u;    // uint[N]: visible depth keys
OPEN3D_SHADER_CONST uint kGeometryStageSplatIndexBinding = 4u;   // uint[N]: visible splat indices
OPEN3D_SHADER_CONST uint kGeometryStageScanBinding = 5u;         // uint[scan words]: all levels
OPEN3D_SHADER_CONST uint kGeometryStageEntryKeysBinding = 6u;    // uint[capacity]: tile index
OPEN3D_SHADER_CONST uint kGeometryStageEntryValuesBinding = 7u;  // uint[capacity]: splat index
OPEN3D_SHADER_CONST uint kGeometryStageSortParamsBinding = 8u;   // RadixSortParams of the next sort
OPEN3D_SHADER_CONST uint kGeometryStageTileCountsBinding = 9u;   // uint[N]: tiles of splat i
// The composite's state (GaussianCompositeState, then uvec2 [begin, end) per tile): the
// per-tile bins' counts, cursors and finally the ranges the composite reads.
OPEN3D_SHADER_CONST uint kGeometryStageTileRangesBinding = 10u;
// The tile sort's RadixSweepState and the sorts' look-back status words (the histogram
// scratch), where the chained emit counts the tile sort's digits and zeroes its first
// pass's status rows in place of the sort's histogram dispatch.
OPEN3D_SHADER_CONST uint kGeometryStageTileSortStateBinding = 11u;
OPEN3D_SHADER_CONST uint kGeometryStageSortStatusBinding = 12u;
// The depth sort's RadixSweepState, where the projection counts its digits (kSpecDepthDigits).
OPEN3D_SHADER_CONST uint kGeometryStageDepthSortStateBinding = 13u;
OPEN3D_SHADER_CONST uint kGeometryStageNumBindings = 14u;

// The buffers a splat count can grow past the range one storage binding reaches
// (maxStorageBufferRange: 4 GiB on NVIDIA, 128 MiB on lavapipe; 98M splats of degree 3 have
// 9.4 GB of SH words, 268M splats 4 GiB of positions), as device addresses split into low and
// high words: the projection reads the positions, shape and SH words and writes the projected
// records, the emit reads those. They sit in the geometry stage's push constants at
// kGeometryAddressesPushOffset, after the scan's and the dispatch-args pass's constants, and
// are pushed with the bindings.
struct GaussianGeometryAddresses {
    uint shape_lo, shape_hi;          // uint[N * shape words]
    uint sh_lo, sh_hi;                // uint[N * sh words]; unread at degree 0
    uint projected_lo, projected_hi;  // GaussianProjectedSplat[N]
    uint positions_lo, positions_hi;  // vec4[N]: xyz, sigmoid(opacity)
};
OPEN3D_SHADER_CONST uint kGeometryAddressesPushOffset = 32u;

// Per-frame view parameters (a readonly std430 storage buffer), one named member per value;
// each vec3 shares its 16 bytes with the scalar after it (GaussianSplatCommon.h).
struct GaussianViewParams {
    // Camera-relative projection: p_cam = R ((p - c_hi) - c_lo) (CameraRelative), exact to
    // float32 rounding of p - c even 1e5 from the origin, where R p + t loses ~1e-2.
    vec3 rotation_row0;  // row 0 of R (world to camera)
    float center_low_x;  // c_lo = float(c - c_hi), the centre's rounding error
    vec3 rotation_row1;  // row 1 of R
    float center_low_y;
    vec3 rotation_row2;  // row 2 of R
    float center_low_z;
    vec3 center_high;  // c_hi, the camera centre rounded to float32
    float reserved0;
    float fx, fy, cx, cy;  // intrinsics (pixels)
    float guard_x;         // guard band half width 1.3 tan(fov_x / 2)
    float guard_y;         // guard band half height 1.3 tan(fov_y / 2)
    float near_plane;
    float packed_depth_scale;  // packed key's 1 / (far - near); 0 = exact depth order
    uint width, height, tiles_x, tiles_y;
    uint entry_capacity;  // tile entries used (<= entry_capacity_allocated)
    uint max_tiles_per_splat;
    uint max_tile_entries_total;  // clamped below 2^31
    uint tile_bits;               // SortKeyTileBits of the tile count
    uint num_splats;
    uint sh_degree;  // SH degree evaluated (== kSpecShDegree of the pipeline)
    uint antialias;  // 0 / 1 (== kSpecAntialias of the pipeline)
    uint sh_words_per_splat;
    uint scene_depth_present;  // 0 / 1
    uint splat_precision;      // kPrecisionExact / kPrecisionCompact
    uint shape_words_per_splat;
    uint entry_capacity_allocated;
    // Row 2 of the original rasterizer's float32 world-to-view matrix [R | t]
    // (ReferenceViewDepth, ReferenceDepthRow).
    float reference_m2, reference_m6, reference_m10, reference_m14;
    uint depth_order;  // kDepthOrderReference / kDepthOrderCameraRelative
    // Nodes the level-of-detail cut may keep (RenderConfig::lod_budget, 0xFFFFFFFF: every
    // leaf); read only for a scene with a hierarchy (GaussianSplatLodContract.h).
    uint lod_budget;
    // Centre of the guard band in x / z and y / z: the image's centre ((W - 1) / 2 - cx) / fx,
    // ((H - 1) / 2 - cy) / fy; 0 for a centred principal point (the original's only case).
    float guard_center_x, guard_center_y;
};

// One projected splat, written for visible splats only, indexed by splat index (std430).
struct GaussianProjectedSplat {
    float center_x, center_y;  // pixels
    float depth;               // view-space z
    float opacity;             // antialias applied
    vec3 conic;                // inverse dilated 2D covariance a, b, c
    float cull_threshold;      // TileCullThreshold of the splat
    vec3 color;                // max(0, 0.5 + SH), not clamped above
    float det_q;               // a c - b^2 of the conic (1 / det of the dilated covariance)
    uint rect_min;             // tile rect [min, max): x | y << 16
    uint rect_max;
    uint num_entries;  // the rect's tiles that TileRowSpan keeps
    uint radius;       // pixels
};

// Bytes of one record as the shaders store it (GaussianProjectedWords).
OPEN3D_SHADER_CONST uint kProjectedSplatBytes = 64u;

// How the shaders store a GaussianProjectedSplat: the same 64 bytes as four 16-byte words,
// so the projection writes it and the emit and composite passes read it with 128-bit
// accesses. Stored member by member, the projection took 1.5-1.8x the time on the H200
// (playbot_125k 0.026 -> 0.038 ms, the 7x7 grid 0.415 -> 0.765 ms; docs/perf/h200.md).
// Shaders go through PackProjectedSplat / UnpackProjectedSplat only.
struct GaussianProjectedWords {
    vec4 center_depth_opacity;
    vec4 conic_cull;
    vec4 color_det;
    uvec4 tiles;
};
#ifndef __cplusplus
GaussianProjectedWords PackProjectedSplat(GaussianProjectedSplat s) {
    GaussianProjectedWords w;
    w.center_depth_opacity = vec4(s.center_x, s.center_y, s.depth, s.opacity);
    w.conic_cull = vec4(s.conic, s.cull_threshold);
    w.color_det = vec4(s.color, s.det_q);
    w.tiles = uvec4(s.rect_min, s.rect_max, s.num_entries, s.radius);
    return w;
}
GaussianProjectedSplat UnpackProjectedSplat(GaussianProjectedWords w) {
    GaussianProjectedSplat s;
    s.center_x = w.center_depth_opacity.x;
    s.center_y = w.center_depth_opacity.y;
    s.depth = w.center_depth_opacity.z;
    s.opacity = w.center_depth_opacity.w;
    s.conic = w.conic_cull.xyz;
    s.cull_threshold = w.conic_cull.w;
    s.color = w.color_det.xyz;
    s.det_q = w.color_det.w;
    s.rect_min = w.tiles.x;
    s.rect_max = w.tiles.y;
    s.num_entries = w.tiles.z;
    s.radius = w.tiles.w;
    return s;
}
#endif

#ifdef __cplusplus
static_assert(sizeof(GaussianViewParams) == 192);
static_assert(offsetof(GaussianViewParams, rotation_row0) == 0);
static_assert(offsetof(GaussianViewParams, center_low_x) == 12);
static_assert(offsetof(GaussianViewParams, rotation_row1) == 16);
static_assert(offsetof(GaussianViewParams, center_low_y) == 28);
static_assert(offsetof(GaussianViewParams, rotation_row2) == 32);
static_assert(offsetof(GaussianViewParams, center_low_z) == 44);
static_assert(offsetof(GaussianViewParams, center_high) == 48);
static_assert(offsetof(GaussianViewParams, reserved0) == 60);
static_assert(offsetof(GaussianViewParams, fx) == 64);
static_assert(offsetof(GaussianViewParams, fy) == 68);
static_assert(offsetof(GaussianViewParams, cx) == 72);
static_assert(offsetof(GaussianViewParams, cy) == 76);
static_assert(offsetof(GaussianViewParams, guard_x) == 80);
static_assert(offsetof(GaussianViewParams, guard_y) == 84);
static_assert(offsetof(GaussianViewParams, near_plane) == 88);
static_assert(offsetof(GaussianViewParams, packed_depth_scale) == 92);
static_assert(offsetof(GaussianViewParams, width) == 96);
static_assert(offsetof(GaussianViewParams, height) == 100);
static_assert(offsetof(GaussianViewParams, tiles_x) == 104);
static_assert(offsetof(GaussianViewParams, tiles_y) == 108);
static_assert(offsetof(GaussianViewParams, entry_capacity) == 112);
static_assert(offsetof(GaussianViewParams, max_tiles_per_splat) == 116);
static_assert(offsetof(GaussianViewParams, max_tile_entries_total) == 120);
static_assert(offsetof(GaussianViewParams, tile_bits) == 124);
static_assert(offsetof(GaussianViewParams, num_splats) == 128);
static_assert(offsetof(GaussianViewParams, sh_degree) == 132);
static_assert(offsetof(GaussianViewParams, antialias) == 136);
static_assert(offsetof(GaussianViewParams, sh_words_per_splat) == 140);
static_assert(offsetof(GaussianViewParams, scene_depth_present) == 144);
static_assert(offsetof(GaussianViewParams, splat_precision) == 148);
static_assert(offsetof(GaussianViewParams, shape_words_per_splat) == 152);
static_assert(offsetof(GaussianViewParams, entry_capacity_allocated) == 156);
static_assert(offsetof(GaussianViewParams, reference_m2) == 160);
static_assert(offsetof(GaussianViewParams, reference_m6) == 164);
static_assert(offsetof(GaussianViewParams, reference_m10) == 168);
static_assert(offsetof(GaussianViewParams, reference_m14) == 172);
static_assert(offsetof(GaussianViewParams, depth_order) == 176);
static_assert(offsetof(GaussianViewParams, lod_budget) == 180);
static_assert(offsetof(GaussianViewParams, guard_center_x) == 184);
static_assert(offsetof(GaussianViewParams, guard_center_y) == 188);
static_assert(sizeof(GaussianGeometryAddresses) == 32);
static_assert(offsetof(GaussianGeometryAddresses, sh_lo) == 8);
static_assert(offsetof(GaussianGeometryAddresses, projected_lo) == 16);
static_assert(offsetof(GaussianGeometryAddresses, positions_lo) == 24);

static_assert(sizeof(GaussianProjectedSplat) == kProjectedSplatBytes);
static_assert(offsetof(GaussianProjectedSplat, center_x) == 0);
static_assert(offsetof(GaussianProjectedSplat, center_y) == 4);
static_assert(offsetof(GaussianProjectedSplat, depth) == 8);
static_assert(offsetof(GaussianProjectedSplat, opacity) == 12);
static_assert(offsetof(GaussianProjectedSplat, conic) == 16);
static_assert(offsetof(GaussianProjectedSplat, cull_threshold) == 28);
static_assert(offsetof(GaussianProjectedSplat, color) == 32);
static_assert(offsetof(GaussianProjectedSplat, det_q) == 44);
static_assert(offsetof(GaussianProjectedSplat, rect_min) == 48);
static_assert(offsetof(GaussianProjectedSplat, rect_max) == 52);
static_assert(offsetof(GaussianProjectedSplat, num_entries) == 56);
static_assert(offsetof(GaussianProjectedSplat, radius) == 60);
// The words hold the members at these same offsets (PackProjectedSplat above).
static_assert(sizeof(GaussianProjectedWords) == sizeof(GaussianProjectedSplat));
}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_PROJECTION_CONTRACT_H
