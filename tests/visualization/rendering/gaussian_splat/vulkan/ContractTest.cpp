// The contract headers compile as C++ (their static_asserts hold) and the GLSL side lays
// the mirrored structs out at the offsets the C++ side asserts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <vector>

#include "GaussianSplatCompositeContract.h"
#include "GaussianSplatTileListContract.h"
#include "VulkanTestFixture.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/ComputePipeline.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/RadixSort.h"
#include "vulkan_test_shaders/TestShaders.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering::vulkan;
namespace shader = visualization::rendering::shader;

TEST(GaussianSplatContract, CompilesAsCpp) {
    // Reaching this line means every static_assert in the header held.
    EXPECT_EQ(shader::kRadixSortBlockSize,
              shader::kRadixSortWorkgroupSize * shader::kRadixSortItemsPerInvocation);
    EXPECT_EQ(sizeof(shader::RadixSortParams), 208u);
    EXPECT_EQ(sizeof(shader::RadixSweepState), 4128u);
    EXPECT_EQ(sizeof(shader::RadixSortPushConstants), 56u);
}

// A producer that counts a one-sweep sort's digits zeroes the first pass's status rows before
// the count is known (the chained emit, RadixSortSmallRows / RadixSortLargeRows): whatever
// the count and however its keys are split between the producer's workgroups, every block
// of the sort RadixSortParamsFor then chooses has its row zeroed, and no row past the table
// (RadixSortMaxBlocks of the capacity) is written. On lavapipe the look-backs run in order and
// never read a stale row, so the suites cannot see a missing one: this checks the rule.
TEST(GaussianSplatContract, ProducerZeroedRowsCoverEverySortBlock) {
    uint32_t state = 2024u;
    const auto random = [&state](uint32_t bound) {
        state = state * 1664525u + 1013904223u;
        return (state >> 8) % bound;
    };
    for (const uint32_t target : {1u, 16u, 100u, 256u, 1000u}) {
        const uint32_t wave =
            std::min(target, shader::kRadixSortTargetBlocks) * shader::kRadixSortBlockSize;
        for (const uint32_t count : {0u, 1u, 255u, 256u, 257u, 2047u, 2048u, 2049u, wave - 1, wave,
                                     wave + 1, wave + 5000u, 3 * wave + 17u}) {
            for (const uint32_t capacity : {count, count + 1u, 2 * count + 3000u, 1u << 22}) {
                const uint32_t table = shader::RadixSortMaxBlocks(capacity, target);
                std::vector<bool> zeroed(table, false);
                const uint32_t small = shader::RadixSortSmallRows(capacity, target);
                ASSERT_LE(small, table);
                for (uint32_t r = 0; r < small; ++r) zeroed[r] = true;
                // Producer workgroups' kept keys: consecutive ranges of 0 to 3,000 keys up to
                // the capacity (the one holding the cut may reach past the count).
                for (uint32_t begin = 0; begin < std::max(count, 1u);) {
                    const uint32_t end = std::min(begin + random(3001u), capacity);
                    const shader::uvec4 rows = shader::RadixSortLargeRows(begin, end, target);
                    ASSERT_LE(rows.y, table) << begin << ".." << end;
                    for (uint32_t r = rows.x; r < rows.y; ++r) zeroed[r] = true;
                    if (end >= capacity) break;
                    begin = end;
                }
                const shader::RadixSortParams params =
                    shader::RadixSortParamsFor(count, capacity, target, 65535u);
                const uint32_t blocks = count == 0 ? 0 : params.num_blocks;
                ASSERT_LE(blocks, table);
                for (uint32_t r = 0; r < blocks; ++r) {
                    ASSERT_TRUE(zeroed[r]) << "target " << target << ", count " << count
                                           << ", capacity " << capacity << ": row " << r;
                }
            }
        }
    }
}

TEST(GaussianSplatContract, ListValuesCarryTheSplatAndItsEntryCount) {
    // The depth sort's values: splat index below ListIndexBits(N), the entry count above it
    // or the sentinel (the scan then gathers tile_counts; the Stress 1080p and 8K cases fail
    // without that fallback). Up to 2^27 splats at least 5 count bits remain, at the sort's
    // largest N (2^30) 2.
    static_assert(RadixSort::kMaxCount <= (1u << 30));
    for (uint32_t n : {1u, 2u, 3u, 255u, 256u, 257u, 31000u, 6125000u, 1u << 24, (1u << 24) + 1u,
                       1u << 27, RadixSort::kMaxCount}) {
        SCOPED_TRACE(n);
        const uint32_t index_bits = shader::ListIndexBits(n);
        EXPECT_GE(index_bits, 1u);
        EXPECT_LT(uint64_t(n - 1), uint64_t(1) << index_bits);  // every index fits
        if (n > 2) {
            EXPECT_GE(uint64_t(n - 1), uint64_t(1) << (index_bits - 1));  // and no more bits
        }
        const uint32_t count_bits = shader::ListCountBits(n);
        EXPECT_GE(count_bits, n <= (1u << 27) ? 5u : 2u);
        EXPECT_LE(count_bits, shader::kListCountMaxBits);
        EXPECT_LE(index_bits + count_bits, 32u);
        const uint32_t sentinel = shader::ListCountSentinel(n);
        EXPECT_EQ(sentinel, (1u << count_bits) - 1u);
        for (uint32_t splat : {0u, n / 2, n - 1}) {
            for (uint32_t count : {0u, 1u, sentinel - 1u, sentinel, sentinel + 1u, 1u << 20}) {
                const uint32_t value = shader::PackListValue(splat, count, n);
                EXPECT_EQ(shader::ListValueSplat(value, n), splat);
                EXPECT_EQ(shader::ListValueCount(value, n), count < sentinel ? count : sentinel);
            }
        }
    }
    EXPECT_EQ(shader::ListIndexBits(6125000u), 23u);  // the grid: 8-bit counts, sentinel 255
    EXPECT_EQ(shader::ListCountSentinel(6125000u), 255u);
    EXPECT_EQ(shader::ListCountBits(1u << 27), 5u);
    EXPECT_EQ(shader::ListCountBits(RadixSort::kMaxCount), 2u);
}

using GaussianSplatContractGpu = VulkanTest;

TEST_F(GaussianSplatContractGpu, ShaderLayoutMatchesCpp) {
    constexpr uint32_t kBindings = 6;
    UniqueDescriptorSetLayout set_layout = CreateStorageBufferPushLayout(Context(), kBindings);
    UniquePipelineLayout layout =
        CreatePipelineLayout(Context(), set_layout.Get(), sizeof(shader::RadixSortPushConstants));
    UniquePipeline pipeline =
        CreateComputePipeline(Context(), layout.Get(), spirv::kContractProbe, "probe");
    Buffer params(Context(), sizeof(shader::RadixSortParams), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                  MemoryUsage::kHostReadback);
    Buffer push_out(Context(), sizeof(shader::RadixSortPushConstants),
                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryUsage::kHostReadback);
    const auto readback = [&](VkDeviceSize size) {
        return Buffer(Context(), size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                      MemoryUsage::kHostReadback);
    };
    Buffer view_out = readback(sizeof(shader::GaussianViewParams));
    Buffer splat_out = readback(sizeof(shader::GaussianProjectedSplat));
    Buffer composite_out = readback(sizeof(shader::GaussianCompositePushConstants));
    Buffer merge_out = readback(sizeof(shader::GaussianDepthMergePushConstants));
    shader::RadixSortPushConstants push{};
    push.shift = 201;
    push.digit_bits = 202;
    push.count_index = 203;
    push.max_count = 204;
    push.target_blocks = 205;
    push.drop_max_keys = 206;
    push.key_range = 207;
    push.num_passes = 208;
    push.values_only = 209;
    push.max_groups_x = 210;
    push.num_bits = 211;
    push.sweep = 212;
    push.run_keys = 213;
    push.run_offset = 214;
    SubmitAndWait(Context(), Pool(), [&](VkCommandBuffer cmd) {
        VkDescriptorBufferInfo infos[kBindings] = {
            {params.Get(), 0, VK_WHOLE_SIZE},        {push_out.Get(), 0, VK_WHOLE_SIZE},
            {view_out.Get(), 0, VK_WHOLE_SIZE},      {splat_out.Get(), 0, VK_WHOLE_SIZE},
            {composite_out.Get(), 0, VK_WHOLE_SIZE}, {merge_out.Get(), 0, VK_WHOLE_SIZE}};
        VkWriteDescriptorSet writes[kBindings] = {};
        for (uint32_t i = 0; i < kBindings; ++i) {
            writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
            writes[i].dstBinding = i;
            writes[i].descriptorCount = 1;
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[i].pBufferInfo = &infos[i];
        }
        Context().GetCmdPushDescriptorSet()(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout.Get(), 0,
                                            kBindings, writes);
        vkCmdPushConstants(cmd, layout.Get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(push), &push);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.Get());
        vkCmdDispatch(cmd, 1, 1, 1);
        RecordMemoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                            VK_ACCESS_2_HOST_READ_BIT);
    });
    shader::RadixSortParams p;
    std::memcpy(&p, params.GetMapped(), sizeof(p));
    EXPECT_EQ(p.dispatch_x, 101u);
    EXPECT_EQ(p.dispatch_y, 102u);
    EXPECT_EQ(p.dispatch_z, 103u);
    EXPECT_EQ(p.count, 104u);
    EXPECT_EQ(p.num_blocks, 105u);
    EXPECT_EQ(p.flags, 106u);
    EXPECT_EQ(p.block_size, 107u);
    EXPECT_EQ(p.key_base, 108u);
    EXPECT_EQ(p.key_min, 114u);
    EXPECT_EQ(p.key_max, 115u);
    EXPECT_EQ(p.range_passes, 109u);
    for (uint32_t pass = 0; pass < shader::kRadixSortMaxPasses; ++pass) {
        SCOPED_TRACE(pass);
        const uint32_t step = 10 * pass;
        EXPECT_EQ(p.pass_blocks[pass].x, 110u + step);
        EXPECT_EQ(p.pass_blocks[pass].w, 113u + step);
        EXPECT_EQ(p.pass_rows[pass].x, 150u + step);
        EXPECT_EQ(p.pass_rows[pass].z, 152u + step);
    }
    EXPECT_EQ(p.copy_blocks.x, 190u);
    EXPECT_EQ(p.copy_blocks.w, 193u);
    EXPECT_EQ(p.sweep_histogram_grid.x, 194u);
    EXPECT_EQ(p.sweep_histogram_grid.w, 197u);
    shader::RadixSortPushConstants q;
    std::memcpy(&q, push_out.GetMapped(), sizeof(q));
    EXPECT_EQ(q.shift, 201u);
    EXPECT_EQ(q.digit_bits, 202u);
    EXPECT_EQ(q.count_index, 203u);
    EXPECT_EQ(q.max_count, 204u);
    EXPECT_EQ(q.target_blocks, 205u);
    EXPECT_EQ(q.drop_max_keys, 206u);
    EXPECT_EQ(q.key_range, 207u);
    EXPECT_EQ(q.num_passes, 208u);
    EXPECT_EQ(q.values_only, 209u);
    EXPECT_EQ(q.max_groups_x, 210u);
    EXPECT_EQ(q.num_bits, 211u);
    EXPECT_EQ(q.sweep, 212u);
    EXPECT_EQ(q.run_keys, 213u);
    EXPECT_EQ(q.run_offset, 214u);

    // The stage structs: every named member at its C++ offset (numbered as the probe writes).
    shader::GaussianViewParams v;
    std::memcpy(&v, view_out.GetMapped(), sizeof(v));
    const float* rotation[3] = {&v.rotation_row0.x, &v.rotation_row1.x, &v.rotation_row2.x};
    const float center_low[3] = {v.center_low_x, v.center_low_y, v.center_low_z};
    for (int row = 0; row < 3; ++row) {
        SCOPED_TRACE(row);
        for (int i = 0; i < 3; ++i) EXPECT_EQ(rotation[row][i], float(300 + 4 * row + i));
        EXPECT_EQ(center_low[row], float(303 + 4 * row));
    }
    EXPECT_EQ(v.center_high.x, 312.0f);
    EXPECT_EQ(v.center_high.z, 314.0f);
    EXPECT_EQ(v.reserved0, 315.0f);
    const float view_floats[] = {v.fx,      v.fy,      v.cx,         v.cy,
                                 v.guard_x, v.guard_y, v.near_plane, v.packed_depth_scale};
    for (int i = 0; i < 8; ++i) EXPECT_EQ(view_floats[i], float(316 + i)) << i;
    const uint32_t view_uints[] = {v.width,
                                   v.height,
                                   v.tiles_x,
                                   v.tiles_y,
                                   v.entry_capacity,
                                   v.max_tiles_per_splat,
                                   v.max_tile_entries_total,
                                   v.tile_bits,
                                   v.num_splats,
                                   v.sh_degree,
                                   v.antialias,
                                   v.sh_words_per_splat,
                                   v.scene_depth_present,
                                   v.splat_precision,
                                   v.shape_words_per_splat,
                                   v.entry_capacity_allocated};
    for (uint32_t i = 0; i < 16; ++i) EXPECT_EQ(view_uints[i], 324u + i) << i;
    EXPECT_EQ(v.reference_m2, 340.0f);
    EXPECT_EQ(v.reference_m6, 341.0f);
    EXPECT_EQ(v.reference_m10, 342.0f);
    EXPECT_EQ(v.reference_m14, 343.0f);
    EXPECT_EQ(v.depth_order, 344u);
    EXPECT_EQ(v.lod_budget, 345u);
    EXPECT_EQ(v.guard_center_x, 346.0f);
    EXPECT_EQ(v.guard_center_y, 347.0f);

    shader::GaussianProjectedSplat s;
    std::memcpy(&s, splat_out.GetMapped(), sizeof(s));
    EXPECT_EQ(s.center_x, 400.0f);
    EXPECT_EQ(s.center_y, 401.0f);
    EXPECT_EQ(s.depth, 402.0f);
    EXPECT_EQ(s.opacity, 403.0f);
    EXPECT_EQ(s.conic.x, 404.0f);
    EXPECT_EQ(s.conic.z, 406.0f);
    EXPECT_EQ(s.cull_threshold, 407.0f);
    EXPECT_EQ(s.color.x, 408.0f);
    EXPECT_EQ(s.color.z, 410.0f);
    EXPECT_EQ(s.det_q, 411.0f);
    EXPECT_EQ(s.rect_min, 412u);
    EXPECT_EQ(s.rect_max, 413u);
    EXPECT_EQ(s.num_entries, 414u);
    EXPECT_EQ(s.radius, 415u);

    shader::GaussianCompositePushConstants c;
    std::memcpy(&c, composite_out.GetMapped(), sizeof(c));
    EXPECT_EQ(c.width, 500u);
    EXPECT_EQ(c.height, 501u);
    EXPECT_EQ(c.tiles_x, 502u);
    EXPECT_EQ(c.tiles_y, 503u);
    EXPECT_EQ(c.count_index, 504u);
    EXPECT_EQ(c.entry_capacity, 505u);
    EXPECT_EQ(c.scene_depth_flip_y, 506u);
    EXPECT_EQ(c.background.x, 508.0f);
    EXPECT_EQ(c.background.z, 510.0f);
    EXPECT_EQ(c.scene_near, 511.0f);

    shader::GaussianDepthMergePushConstants m;
    std::memcpy(&m, merge_out.GetMapped(), sizeof(m));
    EXPECT_EQ(m.width, 600u);
    EXPECT_EQ(m.height, 601u);
    EXPECT_EQ(m.scene_depth_flip_y, 602u);
    EXPECT_EQ(m.near_plane, 604.0f);
    EXPECT_EQ(m.far_plane, 605.0f);
    EXPECT_EQ(m.scene_near, 606.0f);
    EXPECT_EQ(m.min_alpha, 607.0f);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
