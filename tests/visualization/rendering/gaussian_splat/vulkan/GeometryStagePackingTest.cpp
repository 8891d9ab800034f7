// CPU-side geometry stage pieces: the contract layouts, attribute and view-parameter
// packing, fp16 conversion and the tile bits of the sort key. No Vulkan device
// needed.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstddef>

#include "GaussianSplatTileListContract.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "visualization/rendering/gaussian_splat/cpu/SplatTestScene.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
namespace shader = visualization::rendering::shader;

TEST(GeometryStagePacking, ContractLayoutsArePinned) {
    // The same numbers as the static_asserts in GaussianSplatProjectionContract.h, checked at
    // run time too so a layout change shows up as a named test failure.
    EXPECT_EQ(sizeof(shader::GaussianViewParams), 192u);
    EXPECT_EQ(offsetof(shader::GaussianViewParams, entry_capacity), 112u);
    EXPECT_EQ(offsetof(shader::GaussianViewParams, sh_degree), 132u);
    EXPECT_EQ(offsetof(shader::GaussianViewParams, antialias), 136u);
    EXPECT_EQ(offsetof(shader::GaussianViewParams, reference_m2), 160u);
    EXPECT_EQ(offsetof(shader::GaussianViewParams, depth_order), 176u);
    EXPECT_EQ(sizeof(shader::GaussianProjectedSplat), 64u);
    EXPECT_EQ(offsetof(shader::GaussianProjectedSplat, rect_min), 48u);
    EXPECT_EQ(offsetof(shader::GaussianViewParams, lod_budget), 180u);
    // The scan levels, then the level-of-detail cut's counts.
    EXPECT_EQ(sizeof(shader::GaussianGeometryStageCounters), 48u + 16u * shader::kScanMaxLevels);
    EXPECT_EQ(offsetof(shader::GaussianGeometryStageCounters, lod_cut_nodes),
              32u + 16u * shader::kScanMaxLevels);
    EXPECT_EQ(offsetof(shader::GaussianGeometryStageCounters, entry_count),
              4u * shader::kCounterEntriesIndex);
    EXPECT_EQ(sizeof(shader::GaussianScanPushConstants), 32u);
    EXPECT_EQ(shader::kGaussianTileSize, static_cast<uint32_t>(kTileSize));
}

TEST(GeometryStagePacking, SortKeyTileBits) {
    // Real viewports (16x16 tiles): 1080p 120x68, 4K 240x135, 8K 480x270.
    EXPECT_EQ(SortKeyTileBits(120 * 68), 13u);   // 8,160 tiles
    EXPECT_EQ(SortKeyTileBits(240 * 135), 15u);  // 32,400
    EXPECT_EQ(SortKeyTileBits(480 * 270), 17u);  // 129,600
    // Exact powers of two: 2^k - 1 tiles and the filler key fit k bits; 2^k tiles and
    // the filler need k + 1.
    for (uint32_t k = 1; k < 31; ++k) {
        EXPECT_EQ(SortKeyTileBits((uint64_t(1) << k) - 1), k) << k;
        EXPECT_EQ(SortKeyTileBits(uint64_t(1) << k), k + 1) << k;
    }
    EXPECT_EQ(SortKeyTileBits(1), shader::kSortKeyMinTileBits);  // clamped up to 1
    EXPECT_EQ(SortKeyTileBits(uint64_t(1) << 40), shader::kSortKeyMaxTileBits);
}

TEST(GeometryStagePacking, HalfConversion) {
    for (float v : {0.0f, 1.0f, -2.5f, 65504.0f, 6.1035156e-05f, 5.9604645e-08f, 0.1f}) {
        const float back = HalfToFloat(FloatToHalf(v));
        EXPECT_NEAR(back, v, std::abs(v) * 1e-3 + 1e-8) << v;
    }
    EXPECT_EQ(FloatToHalf(1.0f), 0x3C00u);
    EXPECT_EQ(FloatToHalf(-2.0f), 0xC000u);
    EXPECT_EQ(FloatToHalf(1e6f), 0x7C00u);                   // overflow to inf
    EXPECT_EQ(FloatToHalf(1.0f + 1.0f / 2048.0f), 0x3C00u);  // tie to even (down)
    EXPECT_EQ(FloatToHalf(1.0f + 3.0f / 2048.0f), 0x3C02u);  // tie to even (up)
    EXPECT_TRUE(std::isnan(HalfToFloat(FloatToHalf(std::nanf("")))));
    // Every half survives a round trip through float exactly.
    for (uint32_t h = 0; h < 0x10000u; ++h) {
        if ((h & 0x7C00u) == 0x7C00u && (h & 0x3FFu)) continue;  // NaN payloads
        ASSERT_EQ(FloatToHalf(HalfToFloat(uint16_t(h))), h) << h;
    }
}

TEST(GeometryStagePacking, ExactAttributes) {
    TestSplat s;
    s.position = {1, 2, 3};
    s.scale = {0.1, 0.2, 0.3};
    s.rot = {2, 0, 0, 0};  // not normalised: packing normalises
    s.opacity = 0.25;
    s.f_rest.resize(15 * 3);
    for (size_t k = 0; k < s.f_rest.size(); ++k) s.f_rest[k] = 0.01 * double(k);
    const auto cloud = MakeCloud({s, s}, 3);
    const PackedGaussianSplats p = PackGaussianSplatAttrs(cloud);
    ASSERT_EQ(p.num_splats, 2);
    EXPECT_EQ(p.sh_degree, 3);
    EXPECT_EQ(p.shape_words_per_splat, shader::kShapeWordsExact);
    EXPECT_EQ(p.sh_words_per_splat, 45u);
    EXPECT_EQ(p.BytesPerSplat(), 16u + 40u + 180u);
    EXPECT_FLOAT_EQ(p.positions[2], 3.0f);
    EXPECT_FLOAT_EQ(p.positions[3],
                    float(StoredOpacity(0.25)));  // sigmoid applied
    const auto word = [&](size_t k) { return std::bit_cast<float>(p.shape[k]); };
    EXPECT_FLOAT_EQ(word(1), 0.2f);
    EXPECT_FLOAT_EQ(word(3), 1.0f);  // w of the normalised quaternion
    EXPECT_FLOAT_EQ(word(4), 0.0f);
    // SH: [Nc, 3] coefficient-major, channel last, as in the cloud.
    EXPECT_FLOAT_EQ(std::bit_cast<float>(p.sh[45 + 4]), float(0.04));
    EXPECT_EQ(p.visibility, std::vector<uint32_t>{0x3u});
    // Cut to degree 1: only the first 3 coefficients per channel.
    const PackedGaussianSplats d1 = PackGaussianSplatAttrs(cloud, SplatPrecision::kExact, 1);
    EXPECT_EQ(d1.sh_words_per_splat, 9u);
    EXPECT_FLOAT_EQ(std::bit_cast<float>(d1.sh[9 + 8]), float(0.08));
}

TEST(GeometryStagePacking, CompactAttributesFitTheBudget) {
    TestSplat s;
    s.f_rest.assign(45, 0.5);
    const PackedGaussianSplats p =
        PackGaussianSplatAttrs(MakeCloud({s}, 3), SplatPrecision::kCompact);
    EXPECT_EQ(p.shape_words_per_splat, shader::kShapeWordsCompact);
    EXPECT_EQ(p.sh_words_per_splat, 23u);  // 45 halves, padded to a word
    EXPECT_LE(p.BytesPerSplat(), 140u);
    EXPECT_EQ(p.BytesPerSplat(), 16u + 20u + 92u);
    EXPECT_FLOAT_EQ(HalfToFloat(uint16_t(p.sh[0] & 0xFFFF)), 0.5f);
}

TEST(GeometryStagePacking, ViewParams) {
    const auto cam = MakeTestCamera(100, 75);  // fx = fy = 100, principal point (32, 32)
    RenderConfig config;
    config.sh_degree = 2;
    config.antialias = true;
    ViewPackingInputs inputs;
    inputs.num_splats = 7;
    inputs.packed_sh_degree = 3;
    inputs.entry_capacity = 1000;
    const PackedView packed = PackGaussianView(cam, config, inputs);
    const shader::GaussianViewParams& v = packed.params;
    EXPECT_FLOAT_EQ(v.guard_x, float(1.3 * 100 / 200.0));  // 1.3 tan(fov_x / 2) = 1.3 W / 2 fx
    EXPECT_FLOAT_EQ(v.guard_y, float(1.3 * 75 / 200.0));
    EXPECT_FLOAT_EQ(v.near_plane, 0.2f);
    EXPECT_EQ(v.tiles_x, 7u);            // ceil(100 / 16)
    EXPECT_EQ(v.tiles_y, 5u);            // ceil(75 / 16)
    EXPECT_EQ(v.entry_capacity, 1000u);  // the allocation is below max_tile_entries_total
    EXPECT_EQ(v.max_tile_entries_total, uint32_t(config.max_tile_entries_total));
    EXPECT_EQ(v.tile_bits, SortKeyTileBits(35));
    EXPECT_EQ(v.num_splats, 7u);
    EXPECT_EQ(v.sh_degree, 2u);  // min(config 2, packed 3)
    EXPECT_EQ(v.antialias, 1u);
    // The host's choices are the values it packed, not read back from the struct.
    EXPECT_EQ(packed.choices.sh_degree, v.sh_degree);
    EXPECT_TRUE(packed.choices.antialias);
    EXPECT_FALSE(packed.choices.packed_key);
    EXPECT_EQ(packed.choices.tile_bits, v.tile_bits);
    EXPECT_EQ(packed.choices.entry_capacity, v.entry_capacity);
    config.max_tile_entries_total = uint64_t(1) << 40;  // clamped below the scan saturation
    inputs.entry_capacity = 0xFFFFFFFFu;
    EXPECT_LT(PackGaussianViewParams(cam, config, inputs).entry_capacity, shader::kScanSaturation);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
