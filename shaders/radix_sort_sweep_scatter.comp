#version 460
// One pass of the one-sweep sort (RadixSort::Algorithm::kOneSweep): a block ranks its pairs
// by the pass's digit (radix_sort_rank.glsl) and finds, per digit, how many pairs of the
// earlier blocks precede it by decoupled look-back, in the same dispatch:
// 1. its index comes from RadixSweepState::next_block in the order blocks start, so the
//    blocks it waits for have all started;
// 2. invocation d publishes the block's count of digit d in status word (block, d) flagged
//    "aggregate" (block 0: "inclusive"), then walks back over the earlier blocks' words,
//    adding aggregates, until one carries an inclusive prefix (waiting while a word is
//    still 0), and publishes its own inclusive prefix;
// 3. the pass's digit starts come from the global histogram (radix_sort_sweep_histogram),
//    so a pair's output index is digit start + earlier blocks' count + local position.
// A pass whose pairs all share their digit moves nothing: its blocks copy their pairs.
// Status words live in two tables, pass p in table p % 2; each block zeroes its row of the
// other table for the next pass (whose blocks are at most this pass's).
// The first pass reads params.count pairs (dropping kRadixSortDroppedKey keys with
// drop_max_keys); the later passes the kept ones, the histogram's total.
// With run bounds (pc.run_keys != 0, RadixSort::RunBounds) the last pass also leaves, for
// every key below run_keys, the [begin, end) of its run in the sorted output: a block's pairs
// of one key are contiguous in its sorted order (the lower digits are sorted already, and
// the pass is stable), so each run inside a block lowers the key's begin and raises its end
// with one atomic each; runs that span blocks meet in the atomics.
#extension GL_GOOGLE_include_directive : require
#include "radix_sort_common.glsl"

layout(local_size_x = kRadixSortWorkgroupSize) in;

layout(std430, set = 0, binding = kRadixSortParamsBinding) readonly buffer ParamsBlock {
    RadixSortParams params;
};
layout(std430, set = 0, binding = kRadixSortKeysInBinding) readonly buffer KeysInBlock {
    uint keys_in[];
};
layout(std430, set = 0, binding = kRadixSortValuesInBinding) readonly buffer ValuesInBlock {
    uint values_in[];
};
layout(std430, set = 0, binding = kRadixSortKeysOutBinding) writeonly buffer KeysOutBlock {
    uint keys_out[];
};
layout(std430, set = 0, binding = kRadixSortValuesOutBinding) writeonly buffer ValuesOutBlock {
    uint values_out[];
};
// [2][max_blocks][kRadixSortBins] look-back status words, read and written with atomics.
layout(std430, set = 0, binding = kRadixSortHistogramBinding) coherent buffer StatusBlock {
    uint status[];
};
layout(std430, set = 0, binding = kRadixSortSweepStateBinding) coherent buffer SweepStateBlock {
    RadixSweepState state;
};
layout(std430, set = 0, binding = kRadixSortRunBoundsBinding) buffer RunBoundsBlock {
    uint run_bounds[];
};

// kRadixSortBlockSize when the block is reordered in shared memory, else 1 (RadixSort.cpp).
layout(constant_id = kSpecRadixSortLocalCapacity) const uint kLocalCapacity = 1u;
layout(constant_id = kSpecRadixSweepOddBlocksAggregateOnly) const uint kOddBlocksAggregateOnly = 0u;
// kRadixSortBlockSize in the pipeline that writes run bounds without the local reorder.
layout(constant_id = kSpecRadixSortRunCapacity) const uint kRunCapacity = 1u;

shared uint s_block;
shared uint s_identity;                   // 1: every pair of the pass has the same digit
shared uint s_first[kRadixSortBins];      // block-local position of each digit's first pair
shared uint s_out_shift[kRadixSortBins];  // output index - block-local position, per digit
shared uint s_keys[kLocalCapacity];       // the block in sorted order
shared uint s_values[kLocalCapacity];
shared uint s_run_keys[kRunCapacity];  // the block's keys in sorted order, for the run bounds

// Key `key` at sorted output index `out_index` starts and/or ends a run there.
void NoteRun(uint key, uint out_index, bool starts, bool ends) {
    if (key >= pc.run_keys) return;  // e.g. the geometry stage's filler keys
    uint word = pc.run_offset + 2u * key;
    if (starts) atomicMin(run_bounds[word], out_index);
    if (ends) atomicMax(run_bounds[word + 1u], out_index + 1u);
}

#include "radix_sort_rank.glsl"

void main() {
    uint local = gl_LocalInvocationIndex;
    uint pass = pc.shift / kRadixSortDigitBits;
    if (local == 0u) {
        s_block = atomicAdd(state.next_block[pass], 1u);
        s_identity = 0u;
    }
    InitScanSlot();  // its barriers publish s_block
    uint block = s_block;
    uint block_size = params.block_size;
    uint block_begin = block * block_size;
    // Digit starts of this pass; the total is the number of kept pairs.
    uint bin = state.histogram[pass * kRadixSortBins + g_slot];
    uint kept;
    uint digit_base = WorkgroupExclusiveAdd(bin, kept);
    uint count = pass == 0u ? params.count : kept;
    if (block_begin >= count) return;  // uniform: a block past the pairs, or a spare one
    if (bin == count) s_identity = 1u;
    uint block_end = min(block_begin + block_size, count);
    bool write_keys = WritesKeys(pc.num_passes);
    uint table = (pass % 2u) * params.num_blocks * kRadixSortBins;
    if (pass + 1u < pc.num_passes) {
        status[(params.num_blocks * kRadixSortBins - table) + block * kRadixSortBins + local] = 0u;
    }
    barrier();
    bool runs = pc.run_keys != 0u && pass + 1u == pc.num_passes;
    if (s_identity != 0u) {
        for (uint i = block_begin + local; i < block_end; i += kRadixSortWorkgroupSize) {
            uint key = keys_in[i];
            if (write_keys) keys_out[i] = key;
            values_out[i] = values_in[i];
            if (runs) {  // the pairs keep their places: neighbours are the input's
                NoteRun(key, i, i == 0u || keys_in[i - 1u] != key,
                        i + 1u == count || keys_in[i + 1u] != key);
            }
        }
        return;
    }

    uint chunks = block_size / kRadixSortWorkgroupSize;  // uniform, 1..8
    RankBlock(block_begin, block_end, chunks);
    uint pair_totals = ScanSubgroupCounts();
    // Invocation d < kPairWords holds digits 2d and 2d + 1; spread them to one per slot.
    if (local < kPairWords) {
        s_first[2u * local] = pair_totals & 0xFFFFu;
        s_first[2u * local + 1u] = pair_totals >> 16u;
    }
    barrier();
    uint own = s_first[g_slot];  // this block's count of digit g_slot
    uint block_kept;
    uint local_first = WorkgroupExclusiveAdd(own, block_kept);

    // Decoupled look-back for digit g_slot.
    uint word = table + block * kRadixSortBins + g_slot;
    bool aggregate_only = kOddBlocksAggregateOnly != 0u && (block & 1u) == 1u;
    uint prefix = 0u;
    if (block == 0u) {
        atomicExchange(status[word], kRadixSweepFlagInclusive | own);
    } else {
        atomicExchange(status[word], kRadixSweepFlagAggregate | own);
        uint back = block - 1u;
        while (true) {
            uint s = atomicAdd(status[table + back * kRadixSortBins + g_slot], 0u);
            if (s == 0u) continue;  // not published yet: its block has started, wait
            prefix += s & kRadixSweepValueMask;
            if ((s & kRadixSweepFlagInclusive) != 0u) break;
            --back;  // block 0 always publishes an inclusive prefix, so this stops there
        }
        if (!aggregate_only) atomicExchange(status[word], kRadixSweepFlagInclusive | (prefix + own));
    }
    s_first[g_slot] = local_first;
    s_out_shift[g_slot] = digit_base + prefix - local_first;
    barrier();

    for (uint k = 0u; k < kRadixSortItemsPerInvocation; ++k) {
        if (k >= chunks) break;
        if ((g_kept & (1u << k)) == 0u) continue;
        uint digit = DigitOf(g_keys[k]);
        uint position = LocalPosition(k, s_first[digit]);
        if (kLocalCapacity > 1u) {
            s_keys[position] = g_keys[k];
            s_values[position] = g_values[k];
        } else {
            if (write_keys) keys_out[s_out_shift[digit] + position] = g_keys[k];
            values_out[s_out_shift[digit] + position] = g_values[k];
            if (kRunCapacity > 1u && runs) s_run_keys[position] = g_keys[k];
        }
    }
    if (kLocalCapacity == 1u) {
        if (kRunCapacity == 1u || !runs) return;
        barrier();
        for (uint i = local; i < block_kept; i += kRadixSortWorkgroupSize) {
            uint key = s_run_keys[i];
            NoteRun(key, s_out_shift[DigitOf(key)] + i, i == 0u || s_run_keys[i - 1u] != key,
                    i + 1u == block_kept || s_run_keys[i + 1u] != key);
        }
        return;
    }
    barrier();
    for (uint i = local; i < block_kept; i += kRadixSortWorkgroupSize) {
        uint key = s_keys[i];
        uint out_index = s_out_shift[DigitOf(key)] + i;
        if (write_keys) keys_out[out_index] = key;
        values_out[out_index] = s_values[i];
        if (runs) {
            NoteRun(key, out_index, i == 0u || s_keys[i - 1u] != key,
                    i + 1u == block_kept || s_keys[i + 1u] != key);
        }
    }
}
