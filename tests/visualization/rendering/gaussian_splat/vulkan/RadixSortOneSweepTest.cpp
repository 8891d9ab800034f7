// The one-sweep GPU radix sort (RadixSort::Algorithm::kOneSweep: one histogram dispatch, then one
// scatter per pass whose blocks chain by decoupled look-back) against std::stable_sort, on the
// cases the multi-pass sort passes (RadixSortFixture.h), plus what only it does: passes whose
// keys all share their digit copy, and look-backs that walk across blocks that published only
// their own counts.
#include "RadixSortFixture.h"

namespace open3d {
namespace tests {
namespace {

class RadixSortOneSweepTest : public RadixSortFixture<RadixSort::Algorithm::kOneSweep> {};

class RadixSortOneSweepCaseTest : public RadixSortOneSweepTest,
                                  public ::testing::WithParamInterface<SortCase> {};

TEST_P(RadixSortOneSweepCaseTest, MatchesStableSort) {
    RecordProperty("local_reorder", sort_->UsesLocalReorder() ? "yes" : "no");
    CheckSort(GetParam(), /*padding=*/0);
    if (GetParam().count < 100000) CheckSort(GetParam(), /*padding=*/37, /*seed=*/2);
}

INSTANTIATE_TEST_SUITE_P(Counts, RadixSortOneSweepCaseTest, ::testing::ValuesIn(SortCountCases()),
                         [](const auto& info) { return info.param.name; });
INSTANTIATE_TEST_SUITE_P(KeyBits, RadixSortOneSweepCaseTest,
                         ::testing::ValuesIn(SortKeyBitsCases()),
                         [](const auto& info) { return info.param.name; });

TEST_F(RadixSortOneSweepTest, CountAboveCapacityIsClampedAndFlagged) { CheckCountAboveCapacity(); }

TEST_F(RadixSortOneSweepTest, ParamsWrittenByTheProducer) { CheckParamsWrittenByTheProducer(); }

TEST_F(RadixSortOneSweepTest, DropMaxKeysSortsOnlyTheKeptPairs) { CheckDropMaxKeys(); }

TEST_F(RadixSortOneSweepTest, ValuesOnlySortsTheValuesForEveryPassCount) { CheckValuesOnly(); }

TEST_F(RadixSortOneSweepTest, SortsWithBlocksInRowsPastTheWorkgroupLimit) { CheckBlocksInRows(); }

TEST_F(RadixSortOneSweepTest, ReusesScratchAndStateAcrossSorts) {
    // Every sort starts from a cleared state and status rows of its own passes: the results
    // must not depend on the sorts before (different counts, so stale rows would show).
    for (uint32_t seed = 10; seed < 13; ++seed) {
        CheckSort({"", 9000u - 1000u * (seed - 10), Pattern::kRandom}, 5, seed);
    }
}

TEST_F(RadixSortOneSweepTest, LastPassLeavesEachKeysRun) {
    // RadixSort::RunBounds: each key below run_keys gets [begin, end) of its run in the sorted
    // keys, (0xFFFFFFFF, 0) when it has none; keys at and above run_keys (filler) are skipped.
    // Cases: two passes over many blocks, one pass (then the copy back), a last pass whose
    // keys share their digit (it copies), runs across block borders, and the values-only
    // output, whose last pass writes no keys.
    struct RunCase {
        const char* name;
        uint32_t count, num_bits, key_mask, run_keys;
        RadixSort::Output output;
    };
    const RunCase cases[] = {
        {"13 bits, 2 passes", 100000u, 13u, 0x1FFFu, 8000u, RadixSort::Output::kKeysAndValues},
        {"7 bits, 1 pass", 30000u, 7u, 0x7Fu, 100u, RadixSort::Output::kKeysAndValues},
        {"last digit shared", 50000u, 16u, 0x00FFu, 300u, RadixSort::Output::kKeysAndValues},
        {"few long runs", 70000u, 12u, 0x0007u, 8u, RadixSort::Output::kKeysAndValues},
        {"values only", 60000u, 13u, 0x1FFFu, 7000u, RadixSort::Output::kValuesOnly},
    };
    for (const RunCase& c : cases) {
        SCOPED_TRACE(c.name);
        std::vector<uint32_t> keys(c.count), values(c.count);
        uint32_t state = 7;
        for (uint32_t i = 0; i < c.count; ++i) {
            state = state * 1664525u + 1013904223u;
            keys[i] = (state >> 7) & c.key_mask;
            values[i] = i;
        }
        const GpuSortResult gpu =
            Sort(keys, values, c.count, c.num_bits, RadixSort::Params::kSetupPass, nullptr,
                 RadixSort::PassCount::kAll, c.output, c.run_keys);
        std::vector<uint32_t> sorted = keys;
        std::stable_sort(sorted.begin(), sorted.end());
        std::vector<uint32_t> want(2 * size_t(c.run_keys), 0u);
        for (uint32_t k = 0; k < c.run_keys; ++k) want[2 * k] = 0xFFFFFFFFu;
        for (uint32_t i = 0; i < c.count; ++i) {
            const uint32_t k = sorted[i];
            if (k >= c.run_keys) continue;
            want[2 * k] = std::min(want[2 * k], i);
            want[2 * k + 1] = std::max(want[2 * k + 1], i + 1);
        }
        EXPECT_EQ(gpu.run_bounds, want);
    }
}

TEST_F(RadixSortOneSweepTest, PassesWhoseKeysShareTheirDigitCopy) {
    // Keys that differ only in some digits: the passes of the other digits find one non-zero
    // bin in the histogram and copy their blocks. Covers a copy as the first pass (no drop),
    // between sorting passes, as the last pass and for every pass, with and without dropped
    // keys (whose first pass is never a copy), values only.
    struct ShareCase {
        const char* name;
        uint32_t varying_mask;  // the key bits that vary; the rest are fixed
        double drop_fraction;
    };
    const ShareCase cases[] = {
        {"low digit only", 0x000000FFu, 0.0},    // passes 1-3 copy
        {"top digit only", 0xFF000000u, 0.0},    // passes 0-2 copy
        {"middle digits", 0x00FFFF00u, 0.25},    // pass 3 copies, pass 0 drops
        {"one key", 0x00000000u, 0.0},           // every pass copies
        {"one key, dropped", 0x00000000u, 0.5},  // only the first pass moves pairs
        {"depth-like", 0x00FFFFFFu, 0.1},        // the depth sort's usual case
    };
    for (const ShareCase& c : cases) {
        SCOPED_TRACE(c.name);
        const uint32_t n = 50000;
        std::mt19937 rng(n + c.varying_mask);
        std::uniform_real_distribution<double> uniform(0.0, 1.0);
        std::vector<uint32_t> keys(n), values(n);
        std::vector<uint32_t> want_keys, want_values;
        for (uint32_t i = 0; i < n; ++i) {
            keys[i] =
                (0x3E5A7C11u & ~c.varying_mask) | ((rng() % 3001u * 2654435761u) & c.varying_mask);
            values[i] = i;
            if (uniform(rng) < c.drop_fraction) {
                keys[i] = shader::kRadixSortDroppedKey;
            } else {
                want_keys.push_back(keys[i]);
                want_values.push_back(i);
            }
        }
        ReferenceSort(want_keys, want_values, 32);
        const auto kept = static_cast<uint32_t>(want_keys.size());
        const bool drop = c.drop_fraction > 0.0;
        for (RadixSort::Output output :
             {RadixSort::Output::kKeysAndValues, RadixSort::Output::kValuesOnly}) {
            const GpuSortResult gpu =
                Sort(keys, values, n, 32, RadixSort::Params::kWrittenByProducer,
                     drop ? &kept : nullptr, RadixSort::PassCount::kAll, output);
            for (uint32_t i = 0; i < kept; ++i) {
                if (output == RadixSort::Output::kKeysAndValues) {
                    ASSERT_EQ(gpu.keys[i], want_keys[i]) << "key " << i;
                }
                ASSERT_EQ(gpu.values[i], want_values[i]) << "value " << i;
            }
        }
    }
}

TEST_F(RadixSortOneSweepTest, LookBacksWalkAcrossBlocksThatPublishedOnlyTheirCounts) {
    // Odd blocks never publish an inclusive prefix, so the block after one adds its
    // aggregate and walks on. Where workgroups run in order (lavapipe with one thread) this
    // is the only way the aggregate path runs; on a GPU it runs both ways.
    const std::unique_ptr<RadixSort> walking = std::make_unique<RadixSort>(
        Context(), RadixSort::Algorithm::kOneSweep, RadixSortOptions{true});
    sort_.swap(const_cast<std::unique_ptr<RadixSort>&>(walking));
    struct Restore {
        std::unique_ptr<RadixSort>& a;
        std::unique_ptr<RadixSort>& b;
        ~Restore() { a.swap(b); }
    } restore{sort_, const_cast<std::unique_ptr<RadixSort>&>(walking)};
    for (const SortCase& c : {SortCase{"random", 300000, Pattern::kRandom},
                              SortCase{"few distinct", 100000, Pattern::kFewDistinct},
                              SortCase{"tiles", 70000, Pattern::kTiles, 13},
                              SortCase{"odd passes", 40000, Pattern::kRandom, 24}}) {
        SCOPED_TRACE(c.name);
        CheckSort(c, 11);
    }
}

}  // namespace
}  // namespace tests
}  // namespace open3d
