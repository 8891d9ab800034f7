#version 460
// The level-of-detail cut on the GPU (docs/lod.md "The cut on the GPU"), four passes picked
// by kSpecLodPass, mirrored on the CPU by cpu/LodCut.cpp, then two that compact it:
// - sizes: per inner node, the size bucket of its own projected size;
// - buckets: per inner node, its effective bucket, the smallest on its path to the root (so
//   a node opens only where all its ancestors do), and a histogram of what opening it adds
//   to the cut (children - 1) per bucket;
// - threshold: one workgroup finds the lowest bucket t such that opening every node above it
//   keeps the cut within view.lod_budget nodes (1 + the sum of the histogram above t);
// - mask: per inner node, whether it is in the cut (its parent opens, it does not), and when
//   it opens, its leaves (each leaf's parent opens: it is in the cut), set as bits of the
//   zeroed visibility words. One invocation per inner node: a leaf is reached only through
//   its parent's list of children, so the leaves, two thirds of the nodes, are not visited
//   and their parents' buckets are not gathered in the scene's order (see below);
// - counts: per group of 256 nodes, how many of them are in the cut;
// - offsets: per block of 256 groups, the counts' exclusive prefix sums and the block's total;
// - block offsets: one workgroup turns the blocks' totals into exclusive prefix sums;
// - list: per word of 32 nodes, each node of the cut writes its id at its rank, so the list
//   is in node order (the projection's slot order, on which the depth sort's ties depend, is
//   the node order, as when every node had its own slot).
// The walk from the root replaces the sizes, buckets and mask passes on large hierarchies
// (LodCutSearch::kFromRoot): level after level from the root, it sizes only the nodes
// whose parent opens above a guess g, the scene's previous threshold less
// kLodWalkMargin, and opens those above g. Every node above any t >= g is then visited and
// the histogram above g is whole, so the threshold pass finds the same t as over every node
// when t > g (or g = 0); when the budget would open more than g allows (a view that zoomed
// in), it walks again from g = 0. The mask then runs over the visited nodes alone.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "GaussianSplatLodContract.h"

layout(local_size_x = kLodWorkgroupSize) in;
layout(constant_id = kSpecLodPass) const uint kPass = kLodPassBuckets;

layout(push_constant) uniform PushBlock {
    GaussianLodPushConstants pc;
};
layout(std430, set = 0, binding = kLodViewBinding) readonly buffer ViewBlock {
    GaussianViewParams view;
};
layout(std430, set = 0, binding = kLodPositionsBinding) readonly buffer PositionsBlock {
    vec4 positions[];
};
layout(std430, set = 0, binding = kLodNodesBinding) readonly buffer NodesBlock {
    GaussianLodNode nodes[];
};
// [0, inner): each inner node's effective bucket; [inner, 2 inner): its own.
layout(std430, set = 0, binding = kLodBucketsBinding) buffer BucketsBlock {
    uint buckets[];
};
layout(std430, set = 0, binding = kLodHistogramBinding) buffer HistogramBlock {
    uint histogram[];
};
layout(std430, set = 0, binding = kLodCountersBinding) buffer CountersBlock {
    GaussianGeometryStageCounters counters;
};
layout(std430, set = 0, binding = kLodVisibilityBinding) buffer VisibilityBlock {
    uint visibility[];
};
layout(std430, set = 0, binding = kLodGroupCountsBinding) buffer GroupCountsBlock {
    uint group_counts[];
};
layout(std430, set = 0, binding = kLodListBinding) writeonly buffer ListBlock {
    uint list[];
};
layout(std430, set = 0, binding = kLodChildrenBinding) readonly buffer ChildrenBlock {
    uint child_ids[];
};
layout(std430, set = 0, binding = kLodPreviousBinding) buffer PreviousBlock {
    uint previous_threshold;
};
layout(std430, set = 0, binding = kLodWalkBinding) buffer WalkBlock {
    uint walk[];  // kLodWalk* header words, then the visited inner nodes
};

const uint kBucketsPerInvocation = kLodBuckets / kLodWorkgroupSize;
shared uint s_histogram[kLodBuckets];
shared uint s_suffix[kLodWorkgroupSize];
shared uint s_threshold;
shared uint s_append, s_append_base;
shared bool s_last_group;
const uint kWordsPerGroup = kLodWorkgroupSize / 32u;

// Whether the sphere of `radius` about camera-space `c` lies wholly outside one side plane
// x = m z of an image axis spanning [lo, hi] in x / z, widened by 15% of the span and 2 px
// (the projection's 1.3x guard band and the footprint's dilation reach that far).
bool OutsideAxis(float x, float z, float lo, float hi, float focal, float radius) {
    float margin = 0.15 * (hi - lo) + 2.0 / focal;
    lo -= margin;
    hi += margin;
    return (x - lo * z) / sqrt(1.0 + lo * lo) < -radius ||
           (hi * z - x) / sqrt(1.0 + hi * hi) < -radius;
}

// Size bucket of a node (kLodBuckets - 1 largest); 0 when it lies wholly behind the camera or
// outside the frustum.
uint SizeBucket(uint node) {
    vec3 p = positions[node].xyz;
    float radius = nodes[node].radius;
    vec3 c_lo = vec3(view.center_low_x, view.center_low_y, view.center_low_z);
    vec3 rel = vec3(CameraRelative(p.x, view.center_high.x, c_lo.x),
                    CameraRelative(p.y, view.center_high.y, c_lo.y),
                    CameraRelative(p.z, view.center_high.z, c_lo.z));
    vec3 c = vec3(dot(view.rotation_row0, rel), dot(view.rotation_row1, rel),
                  dot(view.rotation_row2, rel));
    if (c.z + radius <= 0.0) return 0u;
    if (OutsideAxis(c.x, c.z, (-0.5 - view.cx) / view.fx,
                    (float(view.width) - 0.5 - view.cx) / view.fx, view.fx, radius) ||
        OutsideAxis(c.y, c.z, (-0.5 - view.cy) / view.fy,
                    (float(view.height) - 0.5 - view.cy) / view.fy, view.fy, radius)) {
        return 0u;
    }
    // A node nearer than its own size counts as up to 1000x its size in pixels.
    float size = max(view.fx, view.fy) * radius / max(c.z, 1e-3 * radius + 1e-30);
    float b = floor((log2(size) + kLodLog2Offset) * float(kLodBucketsPerOctave));
    if (!(b >= 0.0)) return 1u;  // below 2^-32 px (or NaN): the smallest in view
    return uint(min(b, float(kLodBuckets - 2u))) + 1u;
}

// The sum of `own` over lanes 0..lane of the workgroup (Hillis-Steele in s_suffix); every
// lane must call it.
uint InclusivePrefixSum(uint lane, uint own) {
    s_suffix[lane] = own;
    barrier();
    for (uint step = 1u; step < kLodWorkgroupSize; step <<= 1u) {
        uint add = lane >= step ? s_suffix[lane - step] : 0u;
        barrier();
        s_suffix[lane] += add;
        barrier();
    }
    return s_suffix[lane];
}

bool Opens(uint inner, uint threshold) {
    return threshold == kLodOpenAll || buckets[inner] > threshold;
}

// Sets the cut's bits that inner node `inner` decides (its effective bucket and its parent's
// written): its own when its parent opens and it does not, its leaves' when it opens (its
// inner children decide their own).
void MarkCut(uint inner, uint threshold) {
    uint node = pc.num_leaves + inner;
    GaussianLodNode record = nodes[node];
    bool opens = Opens(inner, threshold);
    bool parent_opens =
        record.parent == kLodNoParent || Opens(record.parent - pc.num_leaves, threshold);
    if (parent_opens && !opens) atomicOr(visibility[node / 32u], 1u << (node % 32u));
    if (opens) {
        for (uint k = 0u; k < record.children; ++k) {
            uint child = child_ids[record.first_child + k];
            if (child < pc.num_leaves) atomicOr(visibility[child / 32u], 1u << (child % 32u));
        }
    }
}

// The walk's first level: the root alone.
void StartWalk() {
    walk[kLodWalkHeaderWords] = pc.num_inner - 1u;
    walk[kLodWalkBegin] = 0u;
    walk[kLodWalkEnd] = 1u;
    walk[kLodWalkCursor] = 1u;
    walk[kLodWalkGroupsDone] = 0u;
    walk[kLodWalkArgs] = 1u;
    walk[kLodWalkArgs + 1u] = 1u;
    walk[kLodWalkArgs + 2u] = 1u;
}

void main() {
    // Workgroups in rows past maxComputeWorkGroupCount[0] (DispatchGridFor): every pass
    // takes its workgroup's flat index, and the spare ones of a last row find ids past the end.
    uint flat_group = FlatWorkGroupIndex();
    uint id = flat_group * kLodWorkgroupSize + gl_LocalInvocationID.x;
    uint lane = gl_LocalInvocationID.x;
    if (kPass == kLodPassSizes) {
        if (id < pc.num_inner) buckets[pc.num_inner + id] = SizeBucket(pc.num_leaves + id);
    } else if (kPass == kLodPassBuckets) {
        for (uint b = lane; b < kLodBuckets; b += kLodWorkgroupSize) s_histogram[b] = 0u;
        barrier();
        if (id < pc.num_inner) {
            uint node = pc.num_leaves + id;
            uint bucket = buckets[pc.num_inner + id];
            for (uint up = nodes[node].parent; up != kLodNoParent && bucket > 0u;
                 up = nodes[up].parent) {
                bucket = min(bucket, buckets[pc.num_inner + up - pc.num_leaves]);
            }
            buckets[id] = bucket;
            atomicAdd(s_histogram[bucket], nodes[node].children - 1u);
        }
        barrier();
        for (uint b = lane; b < kLodBuckets; b += kLodWorkgroupSize) {
            if (s_histogram[b] != 0u) atomicAdd(histogram[b], s_histogram[b]);
        }
    } else if (kPass == kLodPassThreshold) {
        // After the walk's second round, or after a first round that found t: nothing to do.
        if (pc.walk != 0u && walk[kLodWalkRound] == kLodWalkDone) return;
        // Lane i owns buckets [16 i, 16 i + 16), read once; the cut when opening above t has
        // 1 + S(t) nodes, S(t) = sum(histogram[b], b > t), falling as t rises. No lane walks
        // the histogram alone: on the H200 a serial loop over its 4096 global words cost
        // more than the rest of the cut.
        uint first = lane * kBucketsPerInvocation;
        uint counts[kBucketsPerInvocation];
        uint own = 0u;
        [[unroll]] for (uint k = 0u; k < kBucketsPerInvocation; ++k) {
            counts[k] = histogram[first + k];
            own += counts[k];
        }
        // Inclusive suffix sums over the lanes (Hillis-Steele), then exclusive: past lane i.
        s_suffix[lane] = own;
        if (lane == 0u) s_threshold = kLodBuckets;
        barrier();
        for (uint step = 1u; step < kLodWorkgroupSize; step <<= 1u) {
            uint add = lane + step < kLodWorkgroupSize ? s_suffix[lane + step] : 0u;
            barrier();
            s_suffix[lane] += add;
            barrier();
        }
        uint total = s_suffix[0];
        uint budget = max(view.lod_budget, 1u);
        uint above = s_suffix[lane] - own;  // S of this lane's last bucket
        uint best = kLodBuckets, best_above = 0u;
        for (uint k = kBucketsPerInvocation; k-- > 0u;) {
            if (above >= budget) break;  // 1 + S(t) > budget from here down
            best = first + k;
            best_above = above;
            above += counts[k];
        }
        if (best != kLodBuckets) atomicMin(s_threshold, best);
        barrier();
        if (pc.walk != 0u) {
            // The walk's histogram holds the nodes above g only: t is the one over every node
            // when t > g, or when g = 0 (bucket 0, outside the view, never opens: the host
            // walks only when the leaves exceed the budget, so not everything fits).
            uint guess = walk[kLodWalkGuess];
            uint threshold = s_threshold;
            if (threshold > guess || guess == 0u) {
                if (best == threshold) {
                    counters.lod_threshold = threshold;
                    counters.lod_cut_nodes = 1u + best_above;
                }
                if (lane == 0u) {
                    uint visited = walk[kLodWalkVisited] + walk[kLodWalkCursor];
                    counters.lod_walk_visited = visited;
                    counters.lod_walks = walk[kLodWalkRound] + 1u;
                    previous_threshold = threshold;
                    walk[kLodWalkRound] = kLodWalkDone;
                    walk[kLodWalkArgs] = 0u;
                    uvec4 mask_grid = DispatchGridFor(
                        (walk[kLodWalkCursor] + kLodWorkgroupSize - 1u) / kLodWorkgroupSize,
                        pc.max_groups_x);
                    walk[kLodWalkMaskArgs] = mask_grid.x;
                    walk[kLodWalkMaskArgs + 1u] = mask_grid.y;
                    walk[kLodWalkMaskArgs + 2u] = 1u;
                }
            } else {
                // The budget opens more than g let the walk see: walk again from g = 0 (the
                // host clears the histogram between the rounds).
                if (lane == 0u) {
                    walk[kLodWalkVisited] += walk[kLodWalkCursor];
                    walk[kLodWalkGuess] = 0u;
                    walk[kLodWalkRound] = 1u;
                    StartWalk();
                }
            }
            return;
        }
        // Everything fits when 1 + the sum over all buckets does: then even the nodes outside
        // the view open and the cut is the leaves.
        if (total < budget) {
            if (lane == 0u) {
                counters.lod_threshold = kLodOpenAll;
                counters.lod_cut_nodes = 1u + total;
            }
        } else if (best == s_threshold) {
            counters.lod_threshold = best;
            counters.lod_cut_nodes = 1u + best_above;
        }
    } else if (kPass == kLodPassMask) {
        // One invocation per inner node (the visibility words were zeroed). The earlier pass,
        // one invocation per node, looked up each leaf's parent bucket: leaves are in the
        // scene's order, so those reads scattered over the inner nodes' buckets.
        if (id < pc.num_inner) {
            MarkCut(id, counters.lod_threshold);
        } else if (pc.num_inner == 0u && id == 0u) {
            atomicOr(visibility[0], 1u);  // a hierarchy of one leaf: the leaf is the cut
        }
    } else if (kPass == kLodPassWalkStart) {
        if (id == 0u) {
            uint previous = min(previous_threshold, kLodBuckets - 1u);
            walk[kLodWalkGuess] = previous > kLodWalkMargin ? previous - kLodWalkMargin : 0u;
            walk[kLodWalkRound] = 0u;
            walk[kLodWalkVisited] = 0u;
            StartWalk();
        }
    } else if (kPass == kLodPassWalk) {
        // kLodWalkNodesPerInvocation nodes of the level per invocation (the workgroup's
        // histogram cleared and added up once for them all); a node's parent (the level
        // before) has its effective bucket written. The opening nodes' inner children are
        // appended, one global atomic per workgroup.
        for (uint b = lane; b < kLodBuckets; b += kLodWorkgroupSize) s_histogram[b] = 0u;
        if (lane == 0u) s_append = 0u;
        barrier();
        uint begin = walk[kLodWalkBegin], end = walk[kLodWalkEnd];
        uint guess = walk[kLodWalkGuess];
        uint first_index =
            begin + flat_group * kLodWorkgroupSize * kLodWalkNodesPerInvocation + lane;
        uint opening[kLodWalkNodesPerInvocation], first_slot[kLodWalkNodesPerInvocation];
        [[unroll]] for (uint r = 0u; r < kLodWalkNodesPerInvocation; ++r) {
            opening[r] = kLodNoParent;
            uint index = first_index + r * kLodWorkgroupSize;
            if (index >= end) continue;
            uint inner = walk[kLodWalkHeaderWords + index];
            uint node = pc.num_leaves + inner;
            GaussianLodNode record = nodes[node];
            uint bucket = SizeBucket(node);
            if (record.parent != kLodNoParent) {
                bucket = min(bucket, buckets[record.parent - pc.num_leaves]);
            }
            buckets[inner] = bucket;
            if (bucket > guess) {
                atomicAdd(s_histogram[bucket], record.children - 1u);
                uint inner_children = 0u;
                for (uint k = 0u; k < record.children; ++k) {
                    if (child_ids[record.first_child + k] >= pc.num_leaves) ++inner_children;
                }
                opening[r] = node;
                first_slot[r] = atomicAdd(s_append, inner_children);
            }
        }
        barrier();
        if (lane == 0u && s_append > 0u) s_append_base = atomicAdd(walk[kLodWalkCursor], s_append);
        barrier();
        [[unroll]] for (uint r = 0u; r < kLodWalkNodesPerInvocation; ++r) {
            if (opening[r] == kLodNoParent) continue;
            GaussianLodNode record = nodes[opening[r]];
            uint slot = kLodWalkHeaderWords + s_append_base + first_slot[r];
            for (uint k = 0u; k < record.children; ++k) {
                uint child = child_ids[record.first_child + k];
                if (child >= pc.num_leaves) walk[slot++] = child - pc.num_leaves;
            }
        }
        for (uint b = lane; b < kLodBuckets; b += kLodWorkgroupSize) {
            if (s_histogram[b] != 0u) atomicAdd(histogram[b], s_histogram[b]);
        }
        // The level's last workgroup to finish makes the next level of the nodes appended
        // (the cursor, read atomically: every workgroup added to it before counting itself
        // done) and sizes its dispatch; a separate one-invocation pass per level cost a
        // dispatch and a barrier more per level.
        if (lane == 0u) {
            memoryBarrierBuffer();  // this workgroup's cursor addition before its count
            // Spare workgroups of the grid count too: they ran with no nodes.
            s_last_group = atomicAdd(walk[kLodWalkGroupsDone], 1u) + 1u == FlatNumWorkGroups();
        }
        barrier();
        if (s_last_group && lane == 0u) {
            uint begin = walk[kLodWalkEnd], end = atomicAdd(walk[kLodWalkCursor], 0u);
            walk[kLodWalkBegin] = begin;
            walk[kLodWalkEnd] = end;
            walk[kLodWalkGroupsDone] = 0u;
            uvec4 grid = DispatchGridFor(LodWalkGroups(end - begin), pc.max_groups_x);
            walk[kLodWalkArgs] = grid.x;
            walk[kLodWalkArgs + 1u] = grid.y;
        }
    } else if (kPass == kLodPassWalkMask) {
        if (id < walk[kLodWalkCursor]) {
            MarkCut(walk[kLodWalkHeaderWords + id], counters.lod_threshold);
        }
    } else if (kPass == kLodPassCounts) {
        // One invocation per group of kLodWorkgroupSize nodes: its words' bits.
        uint total_nodes = pc.num_leaves + pc.num_inner;
        if (id < LodGroups(total_nodes)) {
            uint count = 0u;
            [[unroll]] for (uint k = 0u; k < kWordsPerGroup; ++k) {
                uint word = id * kWordsPerGroup + k;
                if (word * 32u < total_nodes) count += bitCount(visibility[word]);
            }
            group_counts[id] = count;
        }
    } else if (kPass == kLodPassOffsets) {
        // Workgroup b scans the counts of groups [256 b, 256 b + 256) in shared memory into
        // offsets within the block and writes the block's total; the block offsets pass adds
        // the blocks up. (One workgroup walking every group's count took 0.39 ms for the
        // 143k groups of the grid 14x14's 36.7M nodes on an H200.)
        uint groups = LodGroups(pc.num_leaves + pc.num_inner);
        uint own = id < groups ? group_counts[id] : 0u;
        uint inclusive = InclusivePrefixSum(lane, own);
        if (id < groups) group_counts[id] = inclusive - own;
        uint nodes_total = pc.num_leaves + pc.num_inner;
        if (lane == kLodWorkgroupSize - 1u && flat_group < LodBlocks(nodes_total)) {
            group_counts[LodBlockBase(nodes_total) + flat_group] = inclusive;
        }
    } else if (kPass == kLodPassBlockOffsets) {
        // Lane i sums a run of consecutive block totals, the lanes' sums are scanned in
        // shared memory, then each lane writes its run's exclusive offsets: 134M nodes make
        // 2,048 blocks, a run of 8.
        uint nodes_total = pc.num_leaves + pc.num_inner;
        uint base = LodBlockBase(nodes_total), blocks = LodBlocks(nodes_total);
        uint run = (blocks + kLodWorkgroupSize - 1u) / kLodWorkgroupSize;
        uint first = min(lane * run, blocks), last = min(first + run, blocks);
        uint own = 0u;
        for (uint b = first; b < last; ++b) own += group_counts[base + b];
        uint offset = InclusivePrefixSum(lane, own) - own;
        for (uint b = first; b < last; ++b) {
            uint count = group_counts[base + b];
            group_counts[base + b] = offset;
            offset += count;
        }
    } else {
        // The list, one invocation per word of 32 nodes: its cut's nodes go to their group's
        // offset plus the cut's nodes in the group's words before it, in bit order. (An
        // invocation per node launched 32 times the workgroups: 0.44 ms of the 1.15 ms cut of
        // the grid 14x14's 36.7M nodes at 2.45M on an H200.) Slots past the budget cannot be
        // reached: the cut fits it (LodListSlots).
        uint total_nodes = pc.num_leaves + pc.num_inner;
        uint word = id;
        if (word * 32u >= total_nodes) return;
        uint bits = visibility[word];
        if (bits == 0u) return;
        uint group = word / kWordsPerGroup;
        uint rank = group_counts[LodBlockBase(total_nodes) + group / kLodWorkgroupSize] +
                    group_counts[group];
        for (uint k = group * kWordsPerGroup; k < word; ++k) rank += bitCount(visibility[k]);
        while (bits != 0u) {
            uint bit = uint(findLSB(bits));
            bits &= bits - 1u;
            if (rank < pc.list_slots) list[rank] = word * 32u + bit;
            ++rank;
        }
    }
}
