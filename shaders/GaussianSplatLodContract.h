// The level-of-detail cut's part of the GPU contract (GaussianLodCut.cpp,
// GaussianSplatLodPacking.cpp, shaders/gaussian_lod_cut.comp, the CPU mirror cpu/LodCut.cpp):
// the per-node record, the size buckets, the bindings and push constants. A stage of its
// own because only scenes drawn through a hierarchy run it, before the projection, and its
// output is the projection's visibility mask (docs/lod.md "The cut on the GPU").
// GLSL and C++ as GaussianSplatCommon.h says; C++ gets static_asserts on every offset.
#ifndef OPEN3D_SHADERS_GAUSSIAN_SPLAT_LOD_CONTRACT_H
#define OPEN3D_SHADERS_GAUSSIAN_SPLAT_LOD_CONTRACT_H

#include "GaussianSplatTileListContract.h"

#ifdef __cplusplus
namespace open3d {
namespace visualization {
namespace rendering {
namespace shader {
#endif

OPEN3D_SHADER_CONST uint kLodWorkgroupSize = 256u;

// A node's projected size s (pixels: focal x radius / depth) falls in bucket
// 1 + floor((log2(s) + kLodLog2Offset) x kLodBucketsPerOctave), clamped to
// [1, kLodBuckets - 1]: 64 buckets per octave (sizes 1.1% apart) from 2^-32 to 2^32 px.
// Bucket 0 holds the nodes wholly outside the view (opened only when everything is).
OPEN3D_SHADER_CONST uint kLodBuckets = 4096u;
OPEN3D_SHADER_CONST uint kLodBucketsPerOctave = 64u;
OPEN3D_SHADER_CONST float kLodLog2Offset = 32.0;
// GaussianGeometryStageCounters::lod_threshold when every inner node opens (the cut is
// the leaves, the exact scene).
OPEN3D_SHADER_CONST uint kLodOpenAll = 0xFFFFFFFFu;
// GaussianLodNode::parent of the root.
OPEN3D_SHADER_CONST uint kLodNoParent = 0xFFFFFFFFu;

// Passes of gaussian_lod_cut.comp (specialisation constant kSpecLodPass).
OPEN3D_SHADER_CONST uint kSpecLodPass = 0u;
OPEN3D_SHADER_CONST uint kLodPassSizes = 0u;      // per inner node: own size bucket
OPEN3D_SHADER_CONST uint kLodPassBuckets = 1u;    // per inner node: effective bucket, histogram
OPEN3D_SHADER_CONST uint kLodPassThreshold = 2u;  // one workgroup: the bucket to open above
OPEN3D_SHADER_CONST uint kLodPassMask = 3u;       // per node: the cut as visibility bits
OPEN3D_SHADER_CONST uint kLodNumPasses = 4u;

// Descriptor set 0 of the cut's pipelines (one push-descriptor layout).
OPEN3D_SHADER_CONST uint kLodViewBinding = 0u;        // GaussianViewParams
OPEN3D_SHADER_CONST uint kLodPositionsBinding = 1u;   // vec4[nodes]: xyz, sigmoid(opacity)
OPEN3D_SHADER_CONST uint kLodNodesBinding = 2u;       // GaussianLodNode[nodes]
OPEN3D_SHADER_CONST uint kLodBucketsBinding = 3u;     // uint[2 inner]: effective, own bucket
OPEN3D_SHADER_CONST uint kLodHistogramBinding = 4u;   // uint[kLodBuckets]
OPEN3D_SHADER_CONST uint kLodCountersBinding = 5u;    // GaussianGeometryStageCounters
OPEN3D_SHADER_CONST uint kLodVisibilityBinding = 6u;  // uint[ceil(nodes / 32)]: the cut
OPEN3D_SHADER_CONST uint kLodNumBindings = 7u;

// One node of the hierarchy (16 bytes, std430), in node order: leaves 0..N-1 (the scene's
// splats), then the inner nodes N..N+K-1, children before parents, the root last.
struct GaussianLodNode {
    float radius;   // 3 x the largest scale (inner nodes; 0 for leaves, never sized)
    uint parent;    // node id, kLodNoParent for the root
    uint children;  // 0 for a leaf, 2..8 for an inner node
    uint reserved0;
};

struct GaussianLodPushConstants {
    uint num_leaves;
    uint num_inner;
    uint reserved0, reserved1;
};

#ifdef __cplusplus
static_assert(sizeof(GaussianLodNode) == 16);
static_assert(offsetof(GaussianLodNode, parent) == 4);
static_assert(offsetof(GaussianLodNode, children) == 8);
static_assert(sizeof(GaussianLodPushConstants) == 16);
static_assert(kLodWorkgroupSize % 32 == 0, "the mask pass writes whole words");
static_assert(offsetof(GaussianLodPushConstants, num_inner) == 4);
}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_LOD_CONTRACT_H
