#version 460
// Pass 3 of a digit: moves every pair of a block to its sorted position. The block is
// processed in chunks of kRadixSortWorkgroupSize pairs; each chunk is stably ordered by
// digit inside the workgroup with two 4-bit split rounds (one workgroup-wide prefix sum of
// sixteen packed 16-bit counters per round, built from subgroup scans), then written out
// at the digit's running offset. Stability: pairs are loaded in scan-slot order, each
// round keeps equal nibbles in slot order, chunks run in index order and blocks take
// their offsets in block order, so equal digits keep their input order.
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
layout(std430, set = 0, binding = kRadixSortHistogramBinding) readonly buffer HistogramBlock {
    uint histogram[];
};

// Invalid slots of the last chunk get this digit: it is above every real digit of the
// low nibble round and, being last in slot order, ends after every valid pair.
const uint kPastEndDigit = 0xFFu;

shared uint s_digit_offset[kRadixSortBins];  // next output index per digit
shared uint s_run_start[kRadixSortBins];     // first sorted slot of a digit in the chunk
shared uint s_keys[kRadixSortWorkgroupSize];     // by input slot
shared uint s_values[kRadixSortWorkgroupSize];   // by input slot
shared uint s_digits[kRadixSortWorkgroupSize];   // by input slot
shared uint s_order_a[kRadixSortWorkgroupSize];  // input slot at the low-nibble position
shared uint s_order_b[kRadixSortWorkgroupSize];  // input slot at the sorted position

// Sixteen 16-bit counters in two uvec4: counter n lives in word n / 2, half n % 2.
void OneHot(uint nibble, out uvec4 lo, out uvec4 hi) {
    uint word = nibble >> 1u;
    uint bit = 1u << ((nibble & 1u) * 16u);
    uvec4 one = uvec4(equal(uvec4(word & 3u), uvec4(0u, 1u, 2u, 3u))) * bit;
    lo = word < 4u ? one : uvec4(0u);
    hi = word < 4u ? uvec4(0u) : one;
}

uint Counter(uvec4 lo, uvec4 hi, uint nibble) {
    uint word = nibble >> 1u;
    uint packed_word = word < 4u ? lo[word & 3u] : hi[word & 3u];
    return (packed_word >> ((nibble & 1u) * 16u)) & 0xFFFFu;
}

// Stable split by a 4-bit value: returns this slot's position after the round.
uint SplitRank(uint nibble) {
    uvec4 lo, hi, total_lo, total_hi;
    OneHot(nibble, lo, hi);
    WorkgroupExclusiveAdd2(lo, hi, total_lo, total_hi);
    uint start = 0u;
    for (uint n = 0u; n < nibble; ++n) start += Counter(total_lo, total_hi, n);
    return start + Counter(lo, hi, nibble);
}

void main() {
    InitScanSlot();
    uint count = params.count;
    uint num_blocks = params.num_blocks;
    uint block = gl_WorkGroupID.x;

    // Output offset of this block per digit = all smaller digits + earlier blocks' digit.
    {
        uint total;
        uint digit_base = WorkgroupExclusiveAdd(histogram[g_slot], total);
        s_digit_offset[g_slot] =
                digit_base + histogram[kRadixSortBins + g_slot * num_blocks + block];
    }

    uint block_size = params.block_size;
    uint block_begin = block * block_size;
    for (uint chunk_begin = block_begin; chunk_begin < block_begin + block_size;
         chunk_begin += kRadixSortWorkgroupSize) {
        if (chunk_begin >= count) break;  // uniform over the workgroup
        uint num_valid = min(count - chunk_begin, kRadixSortWorkgroupSize);

        uint index = chunk_begin + g_slot;
        bool valid = g_slot < num_valid;
        uint key = valid ? keys_in[index] : 0u;
        uint digit = valid ? DigitOf(key) : kPastEndDigit;
        s_keys[g_slot] = key;
        s_values[g_slot] = valid ? values_in[index] : 0u;
        s_digits[g_slot] = digit;

        // Round 1: low nibble, in input order.
        s_order_a[SplitRank(digit & 15u)] = g_slot;
        barrier();
        // Round 2: high nibble, in round-1 order.
        uint from_a = s_order_a[g_slot];
        s_order_b[SplitRank(s_digits[from_a] >> 4u)] = from_a;
        barrier();

        uint from = s_order_b[g_slot];
        uint sorted_digit = s_digits[from];
        bool sorted_valid = g_slot < num_valid;  // invalid slots sort to the end
        // Runs of equal digits; neighbours are only read for valid slots (< num_valid).
        bool run_begins = sorted_valid &&
                          (g_slot == 0u || s_digits[s_order_b[g_slot - 1u]] != sorted_digit);
        bool run_ends = sorted_valid && (g_slot + 1u == num_valid ||
                                         s_digits[s_order_b[g_slot + 1u]] != sorted_digit);
        if (run_begins) s_run_start[sorted_digit] = g_slot;
        barrier();
        uint rank_in_run = g_slot - s_run_start[sorted_digit];
        if (sorted_valid) {
            uint out_index = s_digit_offset[sorted_digit] + rank_in_run;
            keys_out[out_index] = s_keys[from];
            values_out[out_index] = s_values[from];
        }
        barrier();  // every offset was read before it moves on
        if (run_ends) s_digit_offset[sorted_digit] += rank_in_run + 1u;
        barrier();  // shared arrays are rewritten by the next chunk
    }
}
