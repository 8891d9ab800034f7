// The radix sort tests' fixture (RadixSortTest.cpp: the multi-pass sort, RadixSortOneSweepTest.cpp:
// the one-sweep sort): keys of several patterns, std::stable_sort as the reference, and a sort
// on the GPU whose keys and values must match it exactly, for every count (0, 1, non-multiples
// of the workgroup and block sizes), key pattern and number of key bits. Pairs beyond the
// count must stay untouched.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <numeric>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "GaussianSplatRadixSortContract.h"
#include "VulkanTestFixture.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/RadixSort.h"

namespace open3d {
namespace tests {

using namespace visualization::rendering::vulkan;
namespace shader = visualization::rendering::shader;

enum class Pattern { kRandom, kSorted, kReverse, kAllEqual, kFewDistinct, kTiles };

struct SortCase {
    std::string name;
    uint32_t count;
    Pattern pattern;
    uint32_t num_bits = 32;
};

// Readable parameter in test lists and failures (instead of the struct's bytes).
inline void PrintTo(const SortCase& c, std::ostream* os) {
    *os << c.name << " (" << c.count << " pairs, " << c.num_bits << " bits)";
}

inline std::vector<uint32_t> MakeKeys(const SortCase& c, uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<uint32_t> keys(c.count);
    for (uint32_t i = 0; i < c.count; ++i) {
        switch (c.pattern) {
            case Pattern::kRandom:
                keys[i] = rng();
                break;
            case Pattern::kSorted:
                keys[i] = i * 7919u;
                break;
            case Pattern::kReverse:
                keys[i] = ~(i * 7919u);
                break;
            case Pattern::kAllEqual:
                keys[i] = 0xA5A5A5A5u;
                break;
            case Pattern::kFewDistinct:
                keys[i] = (rng() % 4u) << 29 | 5u;
                break;
            // 1080p tile index in the low 13 bits, random bits above: a tile-only sort.
            case Pattern::kTiles:
                keys[i] = (rng() % 8160u) | (rng() << 13);
                break;
        }
    }
    return keys;
}

/// What the sort must produce: pairs stably ordered by the low num_bits of the key.
inline void ReferenceSort(std::vector<uint32_t>& keys, std::vector<uint32_t>& values,
                          uint32_t num_bits) {
    const uint32_t mask = num_bits >= 32 ? ~0u : (1u << num_bits) - 1u;
    std::vector<uint32_t> order(keys.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(),
                     [&](uint32_t a, uint32_t b) { return (keys[a] & mask) < (keys[b] & mask); });
    std::vector<uint32_t> sorted_keys(keys.size()), sorted_values(keys.size());
    for (size_t i = 0; i < order.size(); ++i) {
        sorted_keys[i] = keys[order[i]];
        sorted_values[i] = values[order[i]];
    }
    keys.swap(sorted_keys);
    values.swap(sorted_values);
}

struct GpuSortResult {
    std::vector<uint32_t> keys;    // [capacity]
    std::vector<uint32_t> values;  // [capacity]
    shader::RadixSortParams params{};
    double gpu_ms = 0.0;  // submit to fence, lavapipe wall time
    /// With run_keys: (begin, end) of each key below run_keys (RadixSort::RunBounds).
    std::vector<uint32_t> run_bounds;
};

/// A suite of one algorithm's sorter (kAlgorithm), made once per suite.
template <RadixSort::Algorithm kAlgorithm>
class RadixSortFixture : public VulkanTest {
protected:
    // The one-sweep sort runs on lavapipe with one thread (SetUpTestSuiteOnOneLavapipeThread).
    static void SetUpTestSuite() {
        if (kAlgorithm == RadixSort::Algorithm::kOneSweep) {
            VulkanTest::SetUpTestSuiteOnOneLavapipeThread();
        } else {
            VulkanTest::SetUpTestSuite();
        }
    }
    void SetUp() override {
        VulkanTest::SetUp();
        if (IsSkipped() || HasFatalFailure()) return;
        if (!sort_) sort_ = std::make_unique<RadixSort>(Context(), kAlgorithm);
        ASSERT_EQ(sort_->GetAlgorithm(), kAlgorithm);
    }
    static void TearDownTestSuite() {
        sort_.reset();
        VulkanTest::TearDownTestSuite();
    }

    /// Sorts keys/values (the whole vectors are the buffers' contents, capacity =
    /// keys.size()) on the GPU with `gpu_count` written into the count buffer on the GPU.
    GpuSortResult Sort(const std::vector<uint32_t>& keys, const std::vector<uint32_t>& values,
                       uint32_t gpu_count, uint32_t num_bits,
                       RadixSort::Params source = RadixSort::Params::kSetupPass,
                       const uint32_t* kept_count = nullptr,
                       RadixSort::PassCount pass_count = RadixSort::PassCount::kAll,
                       RadixSort::Output output = RadixSort::Output::kKeysAndValues,
                       uint32_t run_keys = 0) {
        const auto capacity = static_cast<uint32_t>(keys.size());
        // Run bounds start as (0xFFFFFFFF, 0) pairs after kRunOffset words of something else
        // (written with vkCmdUpdateBuffer: at most 64 KiB, about 8,000 keys).
        constexpr uint32_t kRunOffset = 4;
        const VkDeviceSize run_bytes = 4 * (kRunOffset + 2 * VkDeviceSize(run_keys));
        std::vector<uint32_t> run_init(kRunOffset + 2 * size_t(run_keys), 0u);
        for (uint32_t k = 0; k < run_keys; ++k) run_init[kRunOffset + 2 * k] = 0xFFFFFFFFu;
        const VkDeviceSize bytes = std::max<VkDeviceSize>(capacity, 1) * 4;
        const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                         VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                         VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        Buffer key_buffer(Context(), bytes, usage, MemoryUsage::kDevice);
        Buffer value_buffer(Context(), bytes, usage, MemoryUsage::kDevice);
        // The count sits at byte 20 of its buffer, as it would inside a producer's
        // counter struct; it is written on the GPU, never read back by the sort.
        Buffer count_buffer(Context(), 64, usage, MemoryUsage::kDevice);
        const RadixSortStorageRequirements need = RadixSort::GetStorageRequirements(capacity);
        Buffer keys_alt(Context(), need.keys_alt_bytes, need.scratch_usage, MemoryUsage::kDevice);
        Buffer values_alt(Context(), need.values_alt_bytes, need.scratch_usage,
                          MemoryUsage::kDevice);
        Buffer histogram(Context(), need.histogram_bytes, need.scratch_usage, MemoryUsage::kDevice);
        Buffer sweep_state(Context(), need.sweep_state_bytes, need.sweep_state_usage,
                           MemoryUsage::kDevice);
        Buffer params(
            Context(), need.params_bytes,
            need.params_usage | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
            MemoryUsage::kDevice);
        Buffer upload(Context(), 2 * bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                      MemoryUsage::kHostUpload);
        Buffer readback(Context(), 2 * bytes + sizeof(shader::RadixSortParams) + run_bytes,
                        VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryUsage::kHostReadback);
        Buffer runs(Context(), std::max<VkDeviceSize>(run_bytes, 16), usage, MemoryUsage::kDevice);
        auto* up = static_cast<uint8_t*>(upload.GetMapped());
        if (capacity > 0) {
            std::memcpy(up, keys.data(), capacity * 4);
            std::memcpy(up + bytes, values.data(), capacity * 4);
        }
        CommandPool& pool = Pool();
        CommandBuffer cmd = pool.Allocate();
        cmd.Begin();
        VkCommandBuffer c = cmd.Get();
        if (capacity > 0) {
            VkBufferCopy region{0, 0, capacity * 4u};
            vkCmdCopyBuffer(c, upload.Get(), key_buffer.Get(), 1, &region);
            region.srcOffset = bytes;
            vkCmdCopyBuffer(c, upload.Get(), value_buffer.Get(), 1, &region);
        }
        if (run_keys > 0) vkCmdUpdateBuffer(c, runs.Get(), 0, run_bytes, run_init.data());
        const bool producer = source == RadixSort::Params::kWrittenByProducer;
        // A producer writes the parameters itself (as a shader would); the sort must not
        // read the count then, so the count binding holds garbage.
        vkCmdFillBuffer(c, count_buffer.Get(), 20, 4, producer ? 0xFFFFFFFFu : gpu_count);
        // With a drop, the kept count sits at byte 44 (another count of the same producer).
        if (kept_count) vkCmdFillBuffer(c, count_buffer.Get(), 44, 4, *kept_count);
        if (producer) {
            const shader::RadixSortParams written =
                shader::RadixSortParamsFor(gpu_count, std::max(capacity, 1u),
                                           sort_->GetTargetBlocks(), sort_->GetMaxGroupsX());
            vkCmdUpdateBuffer(c, params.Get(), 0, sizeof(written), &written);
        }
        RecordMemoryBarrier(
            c, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
        RadixSortScratch scratch{keys_alt.Range(), values_alt.Range(), histogram.Range(),
                                 params.Range(), sweep_state.Range()};
        const RadixSort::DropMaxKeys drop{count_buffer.Range(44, 4)};
        RadixSort::RunBounds run_bounds;
        run_bounds.ranges = runs.Range();
        run_bounds.word_offset = kRunOffset;
        run_bounds.num_keys = run_keys;
        sort_->Record(c, key_buffer.Range(), value_buffer.Range(), scratch,
                      count_buffer.Range(20, 4), capacity, num_bits, source,
                      kept_count ? &drop : nullptr, pass_count, output,
                      run_keys > 0 ? &run_bounds : nullptr);
        RecordMemoryBarrier(c, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                            VK_ACCESS_2_TRANSFER_READ_BIT);
        if (capacity > 0) {
            VkBufferCopy region{0, 0, capacity * 4u};
            vkCmdCopyBuffer(c, key_buffer.Get(), readback.Get(), 1, &region);
            region.dstOffset = bytes;
            vkCmdCopyBuffer(c, value_buffer.Get(), readback.Get(), 1, &region);
        }
        VkBufferCopy params_region{0, 2 * bytes, sizeof(shader::RadixSortParams)};
        vkCmdCopyBuffer(c, params.Get(), readback.Get(), 1, &params_region);
        if (run_keys > 0) {
            const VkBufferCopy runs_region{0, 2 * bytes + sizeof(shader::RadixSortParams),
                                           run_bytes};
            vkCmdCopyBuffer(c, runs.Get(), readback.Get(), 1, &runs_region);
        }
        RecordMemoryBarrier(c, VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                            VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        cmd.End();

        UniqueFence fence = CreateFence(Context());
        const auto start = std::chrono::steady_clock::now();
        Submit(Context(), c, fence.Get());
        Wait(Context(), fence.Get());
        GpuSortResult result;
        result.gpu_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        const auto* down = static_cast<const uint8_t*>(readback.GetMapped());
        result.keys.resize(capacity);
        result.values.resize(capacity);
        if (capacity > 0) {
            std::memcpy(result.keys.data(), down, capacity * 4);
            std::memcpy(result.values.data(), down + bytes, capacity * 4);
        }
        std::memcpy(&result.params, down + 2 * bytes, sizeof(result.params));
        if (run_keys > 0) {
            const auto* runs_down = reinterpret_cast<const uint32_t*>(
                down + 2 * bytes + sizeof(shader::RadixSortParams));
            EXPECT_EQ(runs_down[0], 0u) << "the words before the run bounds were written";
            result.run_bounds.assign(runs_down + kRunOffset, runs_down + kRunOffset + 2 * run_keys);
        }
        return result;
    }

    /// Sorts `count` pairs inside buffers of count + padding pairs and checks everything.
    void CheckSort(const SortCase& c, uint32_t padding, uint32_t seed = 1) {
        std::vector<uint32_t> keys = MakeKeys(c, seed);
        std::vector<uint32_t> values(c.count);
        for (uint32_t i = 0; i < c.count; ++i) values[i] = i * 2654435761u + 12345u;  // distinct
        // Pairs past the count: the sort must neither read them into the result nor move them.
        for (uint32_t i = 0; i < padding; ++i) {
            keys.push_back(i);  // small keys that would sort first if they leaked in
            values.push_back(0xDEAD0000u + i);
        }
        GpuSortResult gpu = Sort(keys, values, c.count, c.num_bits);

        std::vector<uint32_t> want_keys(keys.begin(), keys.begin() + c.count);
        std::vector<uint32_t> want_values(values.begin(), values.begin() + c.count);
        ReferenceSort(want_keys, want_values, c.num_bits);
        want_keys.insert(want_keys.end(), keys.begin() + c.count, keys.end());
        want_values.insert(want_values.end(), values.begin() + c.count, values.end());

        if (c.num_bits > 0) {
            EXPECT_EQ(gpu.params.count, c.count);
            EXPECT_EQ(gpu.params.flags, 0u);
            // The setup shader and the C++ compilation of RadixSortParamsFor agree (a
            // producer that writes the parameters itself relies on it), and the blocks fit
            // the histogram that GetStorageRequirements sized.
            const shader::RadixSortParams want = shader::RadixSortParamsFor(
                c.count, c.count + padding, sort_->GetTargetBlocks(), sort_->GetMaxGroupsX());
            EXPECT_EQ(gpu.params.block_size, want.block_size);
            EXPECT_EQ(gpu.params.num_blocks, want.num_blocks);
            EXPECT_EQ(gpu.params.dispatch_x, want.dispatch_x);
            EXPECT_EQ(gpu.params.dispatch_y, want.dispatch_y);
            EXPECT_GE(uint64_t(gpu.params.dispatch_x) * gpu.params.dispatch_y,
                      gpu.params.num_blocks);
            const uint64_t area_words =
                RadixSort::GetStorageRequirements(c.count + padding).histogram_bytes / 4;
            EXPECT_LE(256u + 256u * uint64_t(gpu.params.num_blocks), area_words);
        }
        ASSERT_EQ(gpu.keys.size(), want_keys.size());
        for (size_t i = 0; i < want_keys.size(); ++i) {
            ASSERT_EQ(gpu.keys[i], want_keys[i]) << "key " << i << " of " << c.count;
            ASSERT_EQ(gpu.values[i], want_values[i]) << "value " << i << " of " << c.count;
        }
        if (c.count >= 65536) {
            std::cout << "[ timing   ] " << c.name << ": " << c.count << " pairs, " << c.num_bits
                      << " bits, " << gpu.gpu_ms << " ms submit-to-fence (incl. copies)\n";
        }
    }

    void CheckCountAboveCapacity() {
        std::vector<uint32_t> keys = MakeKeys({"", 3000, Pattern::kRandom}, 7);
        std::vector<uint32_t> values(keys.size());
        std::iota(values.begin(), values.end(), 0u);
        GpuSortResult gpu = Sort(keys, values, /*gpu_count=*/5000, 32);
        EXPECT_EQ(gpu.params.count, 3000u);
        EXPECT_EQ(gpu.params.flags, shader::kErrorCountsClamped);
        ReferenceSort(keys, values, 32);
        EXPECT_EQ(gpu.keys, keys);
        EXPECT_EQ(gpu.values, values);
    }

    void CheckParamsWrittenByTheProducer() {
        // No setup pass: the parameters come from the command buffer (as from a producer
        // shader), and the count binding holds garbage that must not be read.
        for (uint32_t count : {1u, 4097u, 70000u}) {
            std::vector<uint32_t> keys = MakeKeys({"", count, Pattern::kRandom}, count);
            std::vector<uint32_t> values(keys.size());
            std::iota(values.begin(), values.end(), 0u);
            GpuSortResult gpu =
                Sort(keys, values, count, 32, RadixSort::Params::kWrittenByProducer);
            ReferenceSort(keys, values, 32);
            EXPECT_EQ(gpu.params.count, count);
            EXPECT_EQ(gpu.keys, keys) << count;
            EXPECT_EQ(gpu.values, values) << count;
        }
    }

    void CheckDropMaxKeys() {
        // Geometry stage's depth sort: culled slots carry kRadixSortDroppedKey among the visible
        // ones. The first pass leaves them out; the kept pairs come out first, stably sorted, and
        // the params describe them. Cases: 4 passes (as geometry stage), odd pass counts (the copy
        // reads the kept params), producer-written params, nothing or everything dropped, runs of
        // dropped keys longer than a block, and pairs past the count that must stay out.
        struct DropCase {
            uint32_t count;
            uint32_t num_bits;
            double drop_fraction;
            RadixSort::Params source;
        };
        const DropCase cases[] = {
            {70000, 32, 0.17, RadixSort::Params::kWrittenByProducer},
            {70000, 32, 0.17, RadixSort::Params::kSetupPass},
            {300000, 32, 0.5, RadixSort::Params::kWrittenByProducer},
            {5000, 8, 0.3, RadixSort::Params::kSetupPass},
            {5000, 24, 0.3, RadixSort::Params::kSetupPass},
            {5000, 16, 0.0, RadixSort::Params::kSetupPass},
            {5000, 32, 1.0, RadixSort::Params::kSetupPass},
            {257, 32, 0.5, RadixSort::Params::kWrittenByProducer},
        };
        for (const DropCase& c : cases) {
            SCOPED_TRACE(testing::Message() << c.count << " pairs, " << c.num_bits << " bits, "
                                            << c.drop_fraction << " dropped");
            std::mt19937 rng(c.count + c.num_bits);
            std::uniform_real_distribution<double> uniform(0.0, 1.0);
            std::vector<uint32_t> keys(c.count), values(c.count);
            for (uint32_t i = 0; i < c.count; ++i) {
                // Keys below 2^num_bits - 1 with many ties, so stability is tested; a run of
                // dropped keys across the third block of 2048.
                keys[i] =
                    (rng() % 997u) * 4099u & ((c.num_bits >= 32 ? 0u : 1u << c.num_bits) - 2u);
                const bool in_run = i >= 4096 && i < 4096 + 3000 && c.drop_fraction > 0.0;
                if (in_run || uniform(rng) < c.drop_fraction)
                    keys[i] = shader::kRadixSortDroppedKey;
                values[i] = i;
            }
            std::vector<uint32_t> want_keys, want_values;
            for (uint32_t i = 0; i < c.count; ++i) {
                if (keys[i] == shader::kRadixSortDroppedKey) continue;
                want_keys.push_back(keys[i]);
                want_values.push_back(values[i]);
            }
            ReferenceSort(want_keys, want_values, c.num_bits);
            const auto kept = static_cast<uint32_t>(want_keys.size());
            // Small keys past the count would sort first if they leaked in.
            for (uint32_t i = 0; i < 37; ++i) {
                keys.push_back(i);
                values.push_back(0xDEAD0000u + i);
            }
            GpuSortResult gpu = Sort(keys, values, c.count, c.num_bits, c.source, &kept);
            // The multi-pass sort's setup after the first pass rewrites the count to the kept
            // pairs; the one-sweep sort leaves the producer's (its later passes count the
            // histogram's total).
            EXPECT_EQ(gpu.params.count,
                      kAlgorithm == RadixSort::Algorithm::kOneSweep ? c.count : kept);
            EXPECT_EQ(gpu.params.flags, 0u);
            for (uint32_t i = 0; i < kept; ++i) {
                ASSERT_EQ(gpu.keys[i], want_keys[i]) << "key " << i << " of " << kept;
                ASSERT_EQ(gpu.values[i], want_values[i]) << "value " << i << " of " << kept;
            }
            for (uint32_t i = c.count; i < c.count + 37; ++i) {
                ASSERT_EQ(gpu.values[i], 0xDEAD0000u + (i - c.count)) << "pair " << i << " moved";
            }
        }
    }

    void CheckValuesOnly() {
        // Without a key range: one to four passes recorded (the copy of an odd count included).
        for (uint32_t num_bits : {8u, 13u, 24u, 32u}) {
            SCOPED_TRACE(num_bits);
            std::mt19937 rng(num_bits);
            std::vector<uint32_t> keys(30000), values(30000);
            for (uint32_t i = 0; i < keys.size(); ++i) {
                keys[i] =
                    rng() % 5000u * 858993u;  // ties, and digits above num_bits that are carried
                values[i] = i;
            }
            std::vector<uint32_t> want_keys = keys, want_values = values;
            ReferenceSort(want_keys, want_values, num_bits);
            GpuSortResult gpu = Sort(keys, values, static_cast<uint32_t>(keys.size()), num_bits,
                                     RadixSort::Params::kSetupPass, nullptr,
                                     RadixSort::PassCount::kAll, RadixSort::Output::kValuesOnly);
            ASSERT_EQ(gpu.values, want_values);
        }
    }

    void CheckBlocksInRows() {
        // A sorter told that its device holds 3 workgroups along x lays the blocks of every
        // per-block pass (histogram, scatter, the odd pass count's copy) out in rows, with spare
        // workgroups in the last row. It must sort as std::stable_sort does, with the setup's
        // parameters and with the producer's, with dropped keys and the key range's passes.
        BorrowedVulkanHandles handles = BorrowedHandles();
        handles.max_workgroups_x = 3;
        const std::unique_ptr<VulkanContext> narrow = VulkanContext::CreateFromBorrowed(handles);
        std::unique_ptr<RadixSort> rows = std::make_unique<RadixSort>(*narrow, kAlgorithm);
        ASSERT_EQ(rows->GetMaxGroupsX(), 3u);
        sort_.swap(rows);  // Sort() records with sort_; swapped back below
        struct Restore {
            std::unique_ptr<RadixSort>& a;
            std::unique_ptr<RadixSort>& b;
            ~Restore() { a.swap(b); }
        } restore{sort_, rows};
        // 197 blocks of 512 pairs on a GPU (its target of 256 blocks), 66 rows of 3; 50 blocks of
        // 2048 on a CPU device (fewer blocks), 17 rows. One workgroup spare either way.
        const uint32_t n = 196u * 512u + 1u;
        CheckSort({"rows", n, Pattern::kRandom}, 5);
        CheckSort({"rows, tiles", n, Pattern::kTiles, 13}, 0);
        const GpuSortResult shape =
            Sort(MakeKeys({"shape", n, Pattern::kRandom}, 3), std::vector<uint32_t>(n, 0u), n, 8);
        const uint32_t blocks = shape.params.num_blocks;
        EXPECT_EQ(blocks, (n + shape.params.block_size - 1) / shape.params.block_size);
        EXPECT_EQ(shape.params.dispatch_x, 3u);
        EXPECT_EQ(shape.params.dispatch_y, (blocks + 2) / 3);
        EXPECT_EQ(blocks % 3, 2u);  // a spare workgroup in the last row
        // The depth sort's way: the producer's parameters, dropped ~0u keys, the passes the kept
        // keys' range needs, values only.
        std::vector<uint32_t> keys = MakeKeys({"depth", n, Pattern::kRandom}, 4);
        std::vector<uint32_t> values(n);
        uint32_t kept = 0;
        for (uint32_t i = 0; i < n; ++i) {
            values[i] = i;
            if (i % 5 == 0)
                keys[i] = shader::kRadixSortDroppedKey;
            else
                keys[i] = 0x3F000000u + (keys[i] >> 12);  // a 20-bit span: three passes
            kept += keys[i] != shader::kRadixSortDroppedKey;
        }
        const GpuSortResult depth =
            Sort(keys, values, n, 32, RadixSort::Params::kWrittenByProducer, &kept,
                 RadixSort::PassCount::kFromKeyRange, RadixSort::Output::kValuesOnly);
        std::vector<uint32_t> want_keys, want_values;
        for (uint32_t i = 0; i < n; ++i) {
            if (keys[i] == shader::kRadixSortDroppedKey) continue;
            want_keys.push_back(keys[i]);
            want_values.push_back(values[i]);
        }
        ReferenceSort(want_keys, want_values, 32);
        ASSERT_EQ(want_values.size(), kept);
        EXPECT_TRUE(std::equal(want_values.begin(), want_values.end(), depth.values.begin()));
        // The one-sweep sort runs every pass (the key range is the multi-pass sort's).
        if (kAlgorithm == RadixSort::Algorithm::kMultiPass)
            EXPECT_EQ(depth.params.range_passes, 3u);
    }

    static std::unique_ptr<RadixSort> sort_;
};

template <RadixSort::Algorithm kAlgorithm>
std::unique_ptr<RadixSort> RadixSortFixture<kAlgorithm>::sort_;

/// Counts and patterns every sorter must sort as std::stable_sort does.
inline std::vector<SortCase> SortCountCases() {
    return {SortCase{"Random0", 0, Pattern::kRandom},
            SortCase{"Random1", 1, Pattern::kRandom},
            SortCase{"Random2", 2, Pattern::kRandom},
            SortCase{"Random255", 255, Pattern::kRandom},
            SortCase{"Random256", 256, Pattern::kRandom},
            SortCase{"Random257", 257, Pattern::kRandom},
            SortCase{"Random1000", 1000, Pattern::kRandom},
            SortCase{"Random4095", 4095, Pattern::kRandom},
            SortCase{"Random4097", 4097, Pattern::kRandom},
            SortCase{"Random65537", 65537, Pattern::kRandom},
            SortCase{"Random1000000", 1000000, Pattern::kRandom},
            SortCase{"Sorted65537", 65537, Pattern::kSorted},
            SortCase{"Reverse65537", 65537, Pattern::kReverse},
            SortCase{"AllEqual65537", 65537, Pattern::kAllEqual},
            SortCase{"FewDistinct1000", 1000, Pattern::kFewDistinct},
            SortCase{"FewDistinct100000", 100000, Pattern::kFewDistinct}};
}

/// Key widths: 0 bits (nothing recorded) to 31, odd pass counts (a copy back) included.
inline std::vector<SortCase> SortKeyBitsCases() {
    return {SortCase{"Bits0", 1000, Pattern::kRandom, 0},
            SortCase{"Bits1", 5000, Pattern::kRandom, 1},
            SortCase{"Bits5", 5000, Pattern::kRandom, 5},
            SortCase{"Bits8", 5000, Pattern::kRandom, 8},
            SortCase{"Bits13Tiles", 70000, Pattern::kTiles, 13},
            SortCase{"Bits16", 5000, Pattern::kRandom, 16},
            SortCase{"Bits24", 20000, Pattern::kRandom, 24},
            SortCase{"Bits31", 5000, Pattern::kRandom, 31},
            SortCase{"Bits4FewDistinct", 20000, Pattern::kFewDistinct, 4}};
}

}  // namespace tests
}  // namespace open3d
