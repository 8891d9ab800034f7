// The level-of-detail cut's part of the GPU contract (GaussianLodCut.cpp,
// GaussianSplatLodPacking.cpp, shaders/gaussian_lod_cut.comp, the CPU mirror cpu/LodCut.cpp):
// the per-node record, the size buckets, the bindings and push constants. A stage of its
// own because only scenes drawn through a hierarchy run it, before the projection, and its
// output is the list of the cut's nodes the projection reads, one per list slot, in node
// order (docs/lod.md "The cut on the GPU").
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
OPEN3D_SHADER_CONST uint kLodPassSizes = 0u;         // per inner node: own size bucket
OPEN3D_SHADER_CONST uint kLodPassBuckets = 1u;       // per inner node: effective bucket, histogram
OPEN3D_SHADER_CONST uint kLodPassThreshold = 2u;     // one workgroup: the bucket to open above
OPEN3D_SHADER_CONST uint kLodPassMask = 3u;          // per inner node: the cut as bits
OPEN3D_SHADER_CONST uint kLodPassCounts = 4u;        // per group of 256 nodes: the cut's nodes
OPEN3D_SHADER_CONST uint kLodPassOffsets = 5u;       // per 256 groups: offsets in the block, total
OPEN3D_SHADER_CONST uint kLodPassBlockOffsets = 6u;  // one workgroup: block totals -> offsets
OPEN3D_SHADER_CONST uint kLodPassList = 7u;          // per node: the cut's nodes as a list
// The walk from the root (GaussianLodCut::Search::kFromRoot), in place of the first passes:
OPEN3D_SHADER_CONST uint kLodPassWalkStart = 8u;  // one invocation: the guess, the root's level
// Per node of a level: bucket, opens, children; its last workgroup sizes the next level.
OPEN3D_SHADER_CONST uint kLodPassWalk = 9u;
OPEN3D_SHADER_CONST uint kLodPassWalkMask = 10u;  // per visited inner node: the cut as bits
OPEN3D_SHADER_CONST uint kLodNumPasses = 11u;

// The walk's buffer (kLodWalkBinding): kLodWalkHeaderWords words of state, each written
// before it is read in a frame, then the inner nodes visited (inner ids, level after level).
OPEN3D_SHADER_CONST uint kLodWalkGuess = 0u;  // g: the walk opens the nodes above it
OPEN3D_SHADER_CONST uint kLodWalkBegin = 1u;  // the current level: [begin, end)
OPEN3D_SHADER_CONST uint kLodWalkEnd = 2u;
OPEN3D_SHADER_CONST uint kLodWalkCursor = 3u;      // visited nodes appended so far
OPEN3D_SHADER_CONST uint kLodWalkRound = 4u;       // 0: first walk, 1: the walk again, kLodWalkDone
OPEN3D_SHADER_CONST uint kLodWalkVisited = 5u;     // nodes visited by the walks before this one
OPEN3D_SHADER_CONST uint kLodWalkGroupsDone = 6u;  // workgroups of the level that finished
OPEN3D_SHADER_CONST uint kLodWalkArgs = 8u;        // VkDispatchIndirectCommand of the walk pass
OPEN3D_SHADER_CONST uint kLodWalkMaskArgs = 12u;   // and of the walk's mask pass
OPEN3D_SHADER_CONST uint kLodWalkHeaderWords = 16u;
OPEN3D_SHADER_CONST uint kLodWalkDone = 2u;
// The walk guesses the previous threshold less a quarter of an octave (sizes 19% apart): a
// view that zooms in by less than that between frames walks once.
OPEN3D_SHADER_CONST uint kLodWalkMargin = 16u;

// Descriptor set 0 of the cut's pipelines (one push-descriptor layout).
OPEN3D_SHADER_CONST uint kLodViewBinding = 0u;        // GaussianViewParams
OPEN3D_SHADER_CONST uint kLodPositionsBinding = 1u;   // vec4[nodes]: xyz, sigmoid(opacity)
OPEN3D_SHADER_CONST uint kLodNodesBinding = 2u;       // GaussianLodNode[nodes]
OPEN3D_SHADER_CONST uint kLodBucketsBinding = 3u;     // uint[2 inner]: effective, own bucket
OPEN3D_SHADER_CONST uint kLodHistogramBinding = 4u;   // uint[kLodBuckets]
OPEN3D_SHADER_CONST uint kLodCountersBinding = 5u;    // GaussianGeometryStageCounters
OPEN3D_SHADER_CONST uint kLodVisibilityBinding = 6u;  // uint[ceil(nodes / 32)]: the cut
// uint[LodCountWords(nodes)]: the cut's nodes per group (kLodWorkgroupSize nodes, a
// workgroup of the list pass), then their exclusive prefix sums within blocks of
// kLodWorkgroupSize groups; from LodBlockBase(nodes) on, the blocks' totals, then their
// exclusive prefix sums.
OPEN3D_SHADER_CONST uint kLodGroupCountsBinding = 7u;
OPEN3D_SHADER_CONST uint kLodListBinding = 8u;  // uint[LodListSlots]: node of each list slot
// uint[nodes - 1]: every inner node's children, inner nodes in order
// (GaussianLodNode::first_child).
OPEN3D_SHADER_CONST uint kLodChildrenBinding = 9u;
OPEN3D_SHADER_CONST uint kLodWalkBinding = 10u;  // uint[kLodWalkHeaderWords + inner]: the walk
// uint[1], zero at upload: the last threshold the walk found, for the next frame's guess. One
// per scene, shared by the frame slots and views: frames in flight may read it while another
// writes it, and any value is a valid guess (it changes the nodes walked, never the cut).
OPEN3D_SHADER_CONST uint kLodPreviousBinding = 11u;
OPEN3D_SHADER_CONST uint kLodNumBindings = 12u;

// One node of the hierarchy (16 bytes, std430), in node order: leaves 0..N-1 (the scene's
// splats), then the inner nodes N..N+K-1, children before parents, the root last.
struct GaussianLodNode {
    float radius;   // 3 x the largest scale (inner nodes; 0 for leaves, never sized)
    uint parent;    // node id, kLodNoParent for the root
    uint children;  // 0 for a leaf, 2..8 for an inner node
    // Index of the first of its children in the children binding (inner nodes; 0 for leaves):
    // the mask pass marks an opening node's leaves from there.
    uint first_child;
};

struct GaussianLodPushConstants {
    uint num_leaves;
    uint num_inner;
    uint list_slots;  // LodListSlots of the view's budget
    uint walk;        // 1: the threshold pass follows the walk from the root (kLodPassWalk*)
    // The device's maxComputeWorkGroupCount[0]: the walk's grids it writes (DispatchGridFor).
    uint max_groups_x;
};

// Slots of the cut's node list, known before the cut is: the cut never exceeds the budget
// (at least 1, the root) nor the leaves (every node open). The projection, the depth sort
// and the scan run over these slots, not over every node (`lod_budget` as packed:
// kLodOpenAll keeps every leaf).
OPEN3D_SHADER_FUNC uint LodListSlots(uint num_leaves, uint lod_budget) {
    uint budget = lod_budget > 1u ? lod_budget : 1u;
    return num_leaves < budget ? num_leaves : budget;
}

// Nodes of a level each invocation of the walk pass sizes, and the workgroups for a level.
OPEN3D_SHADER_CONST uint kLodWalkNodesPerInvocation = 4u;
OPEN3D_SHADER_FUNC uint LodWalkGroups(uint level_nodes) {
    uint per_group = kLodWorkgroupSize * kLodWalkNodesPerInvocation;
    return (level_nodes + per_group - 1u) / per_group;
}

OPEN3D_SHADER_FUNC uint LodGroups(uint num_nodes) {
    return (num_nodes + kLodWorkgroupSize - 1u) / kLodWorkgroupSize;
}
OPEN3D_SHADER_FUNC uint LodBlocks(uint num_nodes) {
    return (LodGroups(num_nodes) + kLodWorkgroupSize - 1u) / kLodWorkgroupSize;
}
OPEN3D_SHADER_FUNC uint LodBlockBase(uint num_nodes) {
    return LodBlocks(num_nodes) * kLodWorkgroupSize;
}
OPEN3D_SHADER_FUNC uint LodCountWords(uint num_nodes) {
    return LodBlockBase(num_nodes) + LodBlocks(num_nodes);
}

#ifdef __cplusplus
static_assert(sizeof(GaussianLodNode) == 16);
static_assert(offsetof(GaussianLodNode, parent) == 4);
static_assert(offsetof(GaussianLodNode, children) == 8);
static_assert(offsetof(GaussianLodNode, first_child) == 12);
static_assert(sizeof(GaussianLodPushConstants) == 20);
static_assert(offsetof(GaussianLodPushConstants, max_groups_x) == 16);
static_assert(kLodWorkgroupSize % 32 == 0, "the list pass reads whole words");
static_assert(offsetof(GaussianLodPushConstants, num_inner) == 4);
static_assert(offsetof(GaussianLodPushConstants, list_slots) == 8);
static_assert(offsetof(GaussianLodPushConstants, walk) == 12);
}  // namespace shader
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
#endif  // __cplusplus
#endif  // OPEN3D_SHADERS_GAUSSIAN_SPLAT_LOD_CONTRACT_H
