#version 460
// Per-tile bins, last pass: a workgroup per tile orders the tile's entries by
// (depth key, slot). The pair is unique, so the order is the reference's (front to back,
// ties by splat index) whatever order the emit pass's atomics filled the bin in. Then the
// keys become the tile index and the values stay the slots, the layout the composite and
// the tests read, and the tile's words already hold its range [begin, end) (a tile that
// did not fit gets [0, 0)).
// Sorting network: bitonic in its all-ascending form (a "flip" stage pairs i with
// i ^ (k - 1) in blocks of k, then half-cleaners pair i with i ^ j): every comparison puts
// the smaller pair first, so positions past the tile's n entries act as +infinity and the
// comparisons that reach them are skipped. A tile of up to kCapacity entries sorts in
// shared memory; a longer one sorts runs of kCapacity in shared memory and does the
// stages whose distance is kCapacity or more in the entry buffers, in place.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "GaussianSplatTileListContract.h"

layout(local_size_x = kBinSortWorkgroupSize) in;

layout(constant_id = kSpecBinSortCapacity) const uint kCapacity = kBinSortCapacitySmall;

layout(std430, set = 0, binding = kGeometryStageViewBinding) readonly buffer ViewBlock {
    GaussianViewParams view;
};
layout(std430, set = 0, binding = kGeometryStageTileRangesBinding) buffer TileRangesBlock {
    uint tile_bins[];
};
// Coherent: a long tile's in-place stages read what other invocations of the workgroup
// wrote before the barrier.
layout(std430, set = 0, binding = kGeometryStageEntryKeysBinding) coherent buffer EntryKeysBlock {
    uint entry_keys[];
};
layout(std430, set = 0, binding = kGeometryStageEntryValuesBinding) coherent buffer EntryValuesBlock {
    uint entry_values[];
};

shared uvec2 s_items[kCapacity];

// Pairs each invocation compares per stage of a run in shared memory.
const uint kPairsPerInvocation = kCapacity / 2u / kBinSortWorkgroupSize;

bool Less(uvec2 a, uvec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }

// Pair q of a stage: the smaller index i (the bit `log_j` cleared) and its partner.
uvec2 FlipPair(uint q, uint log_half, uint k) {
    uint half_k = k >> 1u;
    uint i = ((q >> log_half) * k) + (q & (half_k - 1u));
    return uvec2(i, i ^ (k - 1u));
}
uvec2 CleanerPair(uint q, uint log_j, uint j) {
    uint i = ((q >> log_j) << (log_j + 1u)) + (q & (j - 1u));
    return uvec2(i, i + j);
}

void CompareShared(uvec2 pair) {
    uvec2 a = s_items[pair.x];
    uvec2 b = s_items[pair.y];
    if (Less(b, a)) {
        s_items[pair.x] = b;
        s_items[pair.y] = a;
    }
}

// Stages of the network over `size` (a power of two, <= kCapacity) items in shared memory:
// with `full`, every block size k from 2 to size (sorts the run); else only the
// half-cleaners j = size / 2 .. 1 (merges a run the global stages left bitonic-split).
void SharedStages(uint size, bool full) {
    uint log_size = findMSB(size);
    uint pairs = size >> 1u;
    uint first_k = full ? 2u : size * 2u;
    uint last_k = full ? size : size * 2u;
    for (uint k = first_k; k <= last_k; k <<= 1u) {
        uint log_k = findMSB(k);
        if (k <= size) {
            [[unroll]] for (uint r = 0u; r < kPairsPerInvocation; ++r) {
                uint q = gl_LocalInvocationIndex + r * kBinSortWorkgroupSize;
                if (q < pairs) CompareShared(FlipPair(q, log_k - 1u, k));
            }
            barrier();
        }
        uint top = k <= size ? k >> 2u : size >> 1u;
        for (uint j = top; j > 0u; j >>= 1u) {
            uint log_j = findMSB(j);
            [[unroll]] for (uint r = 0u; r < kPairsPerInvocation; ++r) {
                uint q = gl_LocalInvocationIndex + r * kBinSortWorkgroupSize;
                if (q < pairs) CompareShared(CleanerPair(q, log_j, j));
            }
            barrier();
        }
        if (k > size) break;
    }
}

// Loads items [base, base + size) of the tile (past n: +infinity) into shared memory.
void LoadRun(uint begin, uint base, uint size, uint n) {
    for (uint i = gl_LocalInvocationIndex; i < size; i += kBinSortWorkgroupSize) {
        uint at = base + i;
        s_items[i] = at < n ? uvec2(entry_keys[begin + at], entry_values[begin + at])
                            : uvec2(0xFFFFFFFFu);
    }
    barrier();
}

void StoreRun(uint begin, uint base, uint size, uint n) {
    for (uint i = gl_LocalInvocationIndex; i < size; i += kBinSortWorkgroupSize) {
        uint at = base + i;
        if (at < n) {
            entry_keys[begin + at] = s_items[i].x;
            entry_values[begin + at] = s_items[i].y;
        }
    }
    barrier();
}

void CompareGlobal(uint begin, uvec2 pair, uint n) {
    if (pair.y >= n) return;  // +infinity there: nothing moves
    uvec2 a = uvec2(entry_keys[begin + pair.x], entry_values[begin + pair.x]);
    uvec2 b = uvec2(entry_keys[begin + pair.y], entry_values[begin + pair.y]);
    if (Less(b, a)) {
        entry_keys[begin + pair.x] = b.x;
        entry_values[begin + pair.x] = b.y;
        entry_keys[begin + pair.y] = a.x;
        entry_values[begin + pair.y] = a.y;
    }
}

void GlobalBarrier() {
    memoryBarrierBuffer();
    barrier();
}

// A tile longer than kCapacity: runs of kCapacity sorted in shared memory, then for each
// larger block size the stages of distance >= kCapacity in place and the rest per run.
void SortLongTile(uint begin, uint n) {
    uint padded = 1u << (findMSB(n - 1u) + 1u);
    for (uint base = 0u; base < n; base += kCapacity) {
        LoadRun(begin, base, kCapacity, n);
        SharedStages(kCapacity, true);
        StoreRun(begin, base, kCapacity, n);
    }
    GlobalBarrier();
    uint pairs = padded >> 1u;
    for (uint k = kCapacity * 2u; k <= padded; k <<= 1u) {
        uint log_half = findMSB(k) - 1u;
        for (uint q = gl_LocalInvocationIndex; q < pairs; q += kBinSortWorkgroupSize) {
            CompareGlobal(begin, FlipPair(q, log_half, k), n);
        }
        GlobalBarrier();
        for (uint j = k >> 2u; j >= kCapacity; j >>= 1u) {
            uint log_j = findMSB(j);
            for (uint q = gl_LocalInvocationIndex; q < pairs; q += kBinSortWorkgroupSize) {
                CompareGlobal(begin, CleanerPair(q, log_j, j), n);
            }
            GlobalBarrier();
        }
        for (uint base = 0u; base < n; base += kCapacity) {
            LoadRun(begin, base, kCapacity, n);
            SharedStages(kCapacity, false);
            StoreRun(begin, base, kCapacity, n);
        }
        GlobalBarrier();
    }
}

void main() {
    uint tile = FlatWorkGroupIndex();
    uint tiles = view.tiles_x * view.tiles_y;
    if (tile >= tiles) return;  // the grid's spare workgroups (whole workgroups: uniform)
    uint word = kBinRangesWordOffset + 2u * tile;
    uint begin = tile_bins[word];
    uint end = tile_bins[word + 1u];
    barrier();  // every invocation has read the range before it may change
    if (begin >= view.entry_capacity) {  // did not fit (the bin scan flagged the frame)
        if (gl_LocalInvocationIndex == 0u) {
            tile_bins[word] = 0u;
            tile_bins[word + 1u] = 0u;
        }
        return;
    }
    uint n = end - begin;
    if (n == 0u) return;
    if (n <= kCapacity) {
        uint size = 1u << (findMSB(max(n, 2u) - 1u) + 1u);
        LoadRun(begin, 0u, size, n);
        SharedStages(size, true);
        for (uint i = gl_LocalInvocationIndex; i < n; i += kBinSortWorkgroupSize) {
            entry_keys[begin + i] = tile;
            entry_values[begin + i] = s_items[i].y;
        }
        return;
    }
    SortLongTile(begin, n);
    for (uint i = gl_LocalInvocationIndex; i < n; i += kBinSortWorkgroupSize) {
        entry_keys[begin + i] = tile;
    }
}
