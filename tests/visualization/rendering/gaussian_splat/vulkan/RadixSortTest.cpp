// The multi-pass GPU radix sort (RadixSort::Algorithm::kMultiPass) against std::stable_sort
// (RadixSortFixture.h), and what only it does: the passes a key range needs.
#include "RadixSortFixture.h"

namespace open3d {
namespace tests {
namespace {

class RadixSortTest : public RadixSortFixture<RadixSort::Algorithm::kMultiPass> {};

class RadixSortCaseTest : public RadixSortTest, public ::testing::WithParamInterface<SortCase> {};

TEST_P(RadixSortCaseTest, MatchesStableSort) {
    // Which scatter path ran: lavapipe writes each chunk directly, GPUs with room for a
    // block in shared memory reorder it there first (the device run covers that path).
    RecordProperty("local_reorder", sort_->UsesLocalReorder() ? "yes" : "no");
    CheckSort(GetParam(), /*padding=*/0);
    if (GetParam().count < 100000) CheckSort(GetParam(), /*padding=*/37, /*seed=*/2);
}

INSTANTIATE_TEST_SUITE_P(Counts, RadixSortCaseTest, ::testing::ValuesIn(SortCountCases()),
                         [](const auto& info) { return info.param.name; });

INSTANTIATE_TEST_SUITE_P(KeyBits, RadixSortCaseTest, ::testing::ValuesIn(SortKeyBitsCases()),
                         [](const auto& info) { return info.param.name; });

TEST_F(RadixSortTest, CountAboveCapacityIsClampedAndFlagged) { CheckCountAboveCapacity(); }

TEST_F(RadixSortTest, ParamsWrittenByTheProducer) { CheckParamsWrittenByTheProducer(); }

TEST_F(RadixSortTest, DropMaxKeysSortsOnlyTheKeptPairs) { CheckDropMaxKeys(); }

TEST_F(RadixSortTest, KeyRangeSkipsThePassesItsSpanDoesNotNeed) {
    // Geometry stage's depth sort: the first pass finds the kept keys' (min, max), the sort orders
    // by key - base (base = min with its low byte cleared) and runs only the passes that
    // span needs; the others get zero workgroups, and an odd count is copied back. Cases:
    // spans of one to four digits, spans that cross a digit boundary of the keys
    // themselves (the top digits of min and max differ, so without the base the skipped
    // pass would have been needed), one key value, no kept key, 24-bit keys (three passes
    // recorded), with and without a drop, setup and producer-written params.
    struct RangeCase {
        uint32_t count;
        uint32_t num_bits;
        uint32_t key_min;  // keys are drawn from [key_min, key_max], both ends included
        uint32_t key_max;
        double drop_fraction;
        RadixSort::Params source;
        uint32_t want_passes;  // counted by hand from the span
    };
    using P = RadixSort::Params;
    const RangeCase cases[] = {
        // Depths 5.17..19.66 as float bits (the grid at 1080p): span 0xF7F167 < 2^24.
        {70000, 32, 0x40A54F00u, 0x419D4067u, 0.17, P::kWrittenByProducer, 3},
        {70000, 32, 0x40A54F00u, 0x419D4067u, 0.0, P::kSetupPass, 3},
        // Span 0x10FF from base 0x40FFFF00: two passes although min and max differ in
        // their top two digits.
        {20000, 32, 0x40FFFFF0u, 0x41000FFFu, 0.3, P::kWrittenByProducer, 2},
        {20000, 32, 0x12345600u, 0x123456FFu, 0.0, P::kSetupPass, 1},  // one digit
        {20000, 32, 0x12345678u, 0x12345678u, 0.2, P::kSetupPass, 1},  // one key value
        {20000, 32, 0x00000000u, 0xFFFFFFFEu, 0.2, P::kSetupPass, 4},  // the whole range
        {20000, 32, 0x01000000u, 0x02000000u, 0.0, P::kSetupPass, 4},  // just past 2^24
        {20000, 32, 0x01000000u, 0x01FFFFFFu, 0.0, P::kSetupPass, 3},  // just below
        {20000, 24, 0x00100000u, 0x0010FFFFu, 0.1, P::kSetupPass, 2},  // 3 recorded
        {20000, 24, 0x00000100u, 0x00FFFFFFu, 0.1, P::kSetupPass, 3},
        {5000, 32, 0x00000100u, 0x00FFFFFFu, 1.0, P::kSetupPass, 1},  // nothing kept
    };
    for (const RangeCase& c : cases) {
        SCOPED_TRACE(testing::Message() << c.count << " pairs, " << c.num_bits << " bits, ["
                                        << std::hex << c.key_min << ", " << c.key_max << "]");
        std::mt19937 rng(c.count + c.key_min);
        std::uniform_real_distribution<double> uniform(0.0, 1.0);
        std::vector<uint32_t> keys(c.count), values(c.count);
        const uint64_t span = uint64_t(c.key_max) - c.key_min;
        const bool drop = c.drop_fraction > 0.0;
        for (uint32_t i = 0; i < c.count; ++i) {
            // Ties from the i % 7 term; both ends kept unless everything is dropped.
            keys[i] =
                static_cast<uint32_t>(c.key_min + (uint64_t(rng()) * 977u + i % 7u) % (span + 1));
            if (i == 1) keys[i] = c.key_min;
            if (i == 2) keys[i] = c.key_max;
            const bool end = (i == 1 || i == 2) && c.drop_fraction < 1.0;
            if (drop && !end && uniform(rng) < c.drop_fraction) {
                keys[i] = shader::kRadixSortDroppedKey;
            }
            values[i] = i;
        }
        std::vector<uint32_t> want_keys, want_values;
        for (uint32_t i = 0; i < c.count; ++i) {
            if (drop && keys[i] == shader::kRadixSortDroppedKey) continue;
            want_keys.push_back(keys[i]);
            want_values.push_back(values[i]);
        }
        ReferenceSort(want_keys, want_values, c.num_bits);
        const auto kept = static_cast<uint32_t>(want_keys.size());
        GpuSortResult gpu = Sort(keys, values, c.count, c.num_bits, c.source,
                                 drop ? &kept : nullptr, RadixSort::PassCount::kFromKeyRange);
        EXPECT_EQ(gpu.params.count, kept);
        EXPECT_EQ(gpu.params.range_passes, c.want_passes);
        if (kept > 0) {
            EXPECT_EQ(gpu.params.key_min, c.key_min);
            EXPECT_EQ(gpu.params.key_max, c.key_max);
            EXPECT_EQ(gpu.params.key_base, c.key_min & ~0xFFu);
        } else {
            EXPECT_GT(gpu.params.key_min, gpu.params.key_max);  // the empty range
        }
        for (uint32_t i = 0; i < kept; ++i) {
            ASSERT_EQ(gpu.keys[i], want_keys[i]) << "key " << i << " of " << kept;
            ASSERT_EQ(gpu.values[i], want_values[i]) << "value " << i << " of " << kept;
        }
        // As geometry stage sorts: the values only. The keys are not checked: the last pass that
        // runs does not write them.
        GpuSortResult values_only =
            Sort(keys, values, c.count, c.num_bits, c.source, drop ? &kept : nullptr,
                 RadixSort::PassCount::kFromKeyRange, RadixSort::Output::kValuesOnly);
        for (uint32_t i = 0; i < kept; ++i) {
            ASSERT_EQ(values_only.values[i], want_values[i]) << "value " << i << " of " << kept;
        }
    }
}

TEST_F(RadixSortTest, ValuesOnlySortsTheValuesForEveryPassCount) { CheckValuesOnly(); }

TEST_F(RadixSortTest, ReusesScratchAcrossSorts) {
    // The same sorter records many sorts; results must not depend on earlier ones.
    for (uint32_t seed = 10; seed < 13; ++seed) CheckSort({"", 9000, Pattern::kRandom}, 5, seed);
}

TEST_F(RadixSortTest, StorageRequirements) {
    const auto need = RadixSort::GetStorageRequirements(10000);
    EXPECT_EQ(need.keys_alt_bytes, 40000u);
    EXPECT_EQ(need.values_alt_bytes, 40000u);
    // Up to kRadixSortTargetBlocks blocks of >= 256 elements: ceil(10000 / 256) = 40 blocks,
    // each with a status word per digit in the one-sweep sort's two tables (more than the
    // multi-pass sort's digit totals and per-block counts).
    EXPECT_EQ(need.histogram_bytes, 2u * 256u * 40u * 4u);
    // Past 256 * 2048 elements the blocks are 2048 long: 2^23 elements -> 4096 blocks.
    EXPECT_EQ(RadixSort::GetStorageRequirements(1u << 23).histogram_bytes, 2u * 256u * 4096u * 4u);
    EXPECT_EQ(need.params_bytes, sizeof(shader::RadixSortParams));
    EXPECT_EQ(need.sweep_state_bytes, sizeof(shader::RadixSweepState));
    EXPECT_TRUE(need.sweep_state_usage & VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    EXPECT_TRUE(need.params_usage & VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    EXPECT_GT(RadixSort::GetStorageRequirements(0).keys_alt_bytes, 0u);  // no empty buffers
    EXPECT_THROW(RadixSort::GetStorageRequirements(RadixSort::kMaxCount + 1), core::Open3DError);
    EXPECT_NO_THROW(RadixSort::GetStorageRequirements(RadixSort::kMaxCount));
    EXPECT_EQ(RadixSort::GetNumPasses(32), 4u);
    EXPECT_EQ(RadixSort::GetNumPasses(13), 2u);
    EXPECT_EQ(RadixSort::GetNumPasses(0), 0u);
}

TEST_F(RadixSortTest, TheDeviceLimitFollowsItsBindingLimit) {
    // Keys within one binding, at most kMaxCount; the blocks' workgroups go in rows past
    // maxComputeWorkGroupCount[0], which therefore bounds nothing.
    EXPECT_EQ(RadixSort::MaxCountFor(uint64_t(1) << 27), 33554432u);  // lavapipe
    EXPECT_EQ(RadixSort::MaxCountFor(0xFFFFFFFFull), 1073741823u);    // NVIDIA
    EXPECT_EQ(RadixSort::MaxCountFor(uint64_t(1) << 40), RadixSort::kMaxCount);
    const VulkanDeviceInfo& info = Context().GetDeviceInfo();
    EXPECT_EQ(sort_->GetMaxCount(), RadixSort::MaxCountFor(info.max_storage_buffer_range));
    EXPECT_EQ(sort_->GetMaxGroupsX(), info.max_compute_workgroups_x);
    EXPECT_GE(info.max_compute_workgroups_x, 65535u);  // Vulkan's minimum
}

TEST_F(RadixSortTest, SortsWithBlocksInRowsPastTheWorkgroupLimit) { CheckBlocksInRows(); }

TEST_F(RadixSortTest, SortsPastTheSmallestDispatchLimitWhereTheDeviceAllows) {
    // 65,538 blocks of 2048 pairs: more workgroups than the 65,535 every device takes, so
    // where the device allows it (NVIDIA: 2^31 - 1 along x) the sort dispatches them. Where
    // not (lavapipe: 33.5M pairs by its binding range), Record refuses the count
    // (RejectsMisuse) and there is nothing more to check here.
    const uint32_t n = 65535u * 2048u + 4097u;
    if (sort_->GetMaxCount() < n) return;
    // 12-bit keys (two passes) from a hash of the index, values the index: the stable order
    // is known without sorting on the host. Keys ascend, values ascend within a key, every
    // value keeps its own key, and each key keeps its count: a stable permutation.
    const auto key_of = [](uint32_t i) { return (i * 2654435761u) >> 20; };
    std::vector<uint32_t> keys(n), values(n);
    std::vector<uint32_t> counts(1u << 12, 0u);
    for (uint32_t i = 0; i < n; ++i) {
        keys[i] = key_of(i);
        values[i] = i;
        ++counts[keys[i]];
    }
    const GpuSortResult result = Sort(keys, values, n, 12);
    EXPECT_EQ(result.params.count, n);
    EXPECT_EQ(result.params.num_blocks, 65538u);
    std::vector<uint32_t> seen(1u << 12, 0u);
    uint64_t wrong = 0;
    for (uint32_t j = 0; j < n; ++j) {
        const uint32_t key = result.keys[j], value = result.values[j];
        bool ok = value < n && key_of(value) == key;
        if (j > 0) {
            const uint32_t prev_key = result.keys[j - 1];
            ok = ok && (prev_key < key || (prev_key == key && result.values[j - 1] < value));
        }
        if (key < seen.size()) ++seen[key];
        wrong += ok ? 0 : 1;
    }
    EXPECT_EQ(wrong, 0u);
    EXPECT_TRUE(seen == counts);
}

TEST_F(RadixSortTest, RejectsMisuse) {
    Buffer buffer(Context(), 1 << 16,
                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                  MemoryUsage::kDevice);
    RadixSortScratch scratch{buffer.Range(0, 4096), buffer.Range(4096, 4096),
                             buffer.Range(8192, 8192), buffer.Range(16384, 256),
                             buffer.Range(20480, 8192)};
    CommandBuffer cmd = Pool().Allocate();
    cmd.Begin();
    // Nothing is recorded when the arguments are wrong.
    EXPECT_THROW(sort_->Record(cmd.Get(), buffer.Range(32768, 4096), buffer.Range(40960, 4096),
                               scratch, buffer.Range(60000, 4), 1000, 33),
                 core::Open3DError);
    EXPECT_THROW(sort_->Record(cmd.Get(), buffer.Range(32768, 4096), buffer.Range(40960, 4096),
                               scratch, buffer.Range(60000, 4), 2000, 32),
                 core::Open3DError);  // 8000 bytes needed, 4096 given
    EXPECT_THROW(sort_->Record(cmd.Get(), buffer.Range(32772, 4000), buffer.Range(40960, 4096),
                               scratch, buffer.Range(60000, 4), 1000, 32),
                 core::Open3DError);  // misaligned keys
    // More pairs than this device binds: refused first, naming its limit.
    try {
        sort_->Record(cmd.Get(), buffer.Range(32768, 4096), buffer.Range(40960, 4096), scratch,
                      buffer.Range(60000, 4), sort_->GetMaxCount() + 1, 32);
        ADD_FAILURE() << "a sort past the device's " << sort_->GetMaxCount() << " pairs";
    } catch (const core::Open3DError& e) {
        EXPECT_NE(std::string(e.what()).find("maxStorageBufferRange"), std::string::npos)
            << e.what();
    }
    cmd.End();
}

}  // namespace
}  // namespace tests
}  // namespace open3d
