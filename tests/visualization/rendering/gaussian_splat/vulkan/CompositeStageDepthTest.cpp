// Composite stage's scene-depth test and depth merge against synthetic depth textures in Filament's
// convention (reversed-Z, d = near / z_view, 0 = nothing drawn), in isolation from geometry stage.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "CompositeStageTestUtil.h"
#include "VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using rendering::cpu::BuildTileLists;
using rendering::cpu::ProjectedSplat;
using rendering::cpu::TileGrid;

constexpr int kWidth = 40;
constexpr int kHeight = 24;
constexpr float kNear = 0.5f;  // near plane of the synthetic "Filament" projection

// A red splat at z = 2 and a blue one at z = 6 behind it, both covering the image.
std::vector<ProjectedSplat> TwoLayers() {
    return {MakeSplat(20.0, 12.0, 2.0, 6.0, 0.5, {1.0, 0.0, 0.0}, kWidth, kHeight),
            MakeSplat(20.0, 12.0, 6.0, 6.0, 0.9, {0.0, 0.0, 1.0}, kWidth, kHeight)};
}

// Left half: a mesh at view z = 4 (between the splats); right half: nothing drawn.
std::vector<float> ReversedZ() {
    std::vector<float> d(size_t(kWidth) * kHeight, 0.f);
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth / 2; ++x) d[size_t(y) * kWidth + x] = kNear / 4.0f;
    }
    return d;
}

// The same scene depth as view z for the reference (+inf where nothing is drawn).
std::vector<float> LinearZ(const std::vector<float>& reversed) {
    std::vector<float> z(reversed.size());
    for (size_t i = 0; i < z.size(); ++i) {
        z[i] = reversed[i] > 0.f ? kNear / reversed[i] : std::numeric_limits<float>::infinity();
    }
    return z;
}

class CompositeStageDepth : public VulkanTest {
protected:
    gpu::CompositeStageReadback Run(const gpu::CompositeStageRunInputs& in) {
        gpu::GaussianCompositeStageRunner runner(Context());
        return runner.Run(in);
    }
};

TEST_F(CompositeStageDepth, SplatsBehindTheSceneVanishPixelExactly) {
    const auto splats = TwoLayers();
    const auto lists = BuildTileLists(splats, TileGrid::ForImage(kWidth, kHeight), {});
    for (const bool flip_y : {false, true}) {
        SCOPED_TRACE(flip_y ? "texture stored bottom row first" : "top row first");
        gpu::CompositeStageRunInputs in = ToCompositeStageInputs(splats, lists, kWidth, kHeight);
        in.scene_depth = ReversedZ();
        in.scene_near = kNear;
        in.scene_depth_flip_y = flip_y;
        const auto out = Run(in);
        const auto ref =
            ReferenceComposite(splats, lists, kWidth, kHeight, {}, LinearZ(in.scene_depth));
        // Same float32 rules as the analytic cases (CompositeStageCompositeTest.cpp): <= 1e-6.
        EXPECT_LE(CompareImage(out.color, ref.color).max_abs, 1e-6);
        EXPECT_LE(CompareImage(out.depth, ref.depth_expected).max_abs, 1e-5);
        for (int y = 0; y < kHeight; ++y) {
            for (int x = 0; x < kWidth; ++x) {
                const size_t i = size_t(y) * kWidth + x;
                const float alpha_front = out.alpha[i];
                if (x < kWidth / 2) {
                    // Behind the mesh: the blue splat is gone, exactly.
                    ASSERT_EQ(out.color[4 * i + 2], 0.f) << x << ", " << y;
                    ASSERT_LE(out.depth[i], 2.0f * (1.0f + 1e-6f));  // z w / w: 1 ulp
                } else if (alpha_front > 0.5f) {
                    ASSERT_GT(out.color[4 * i + 2], 0.f) << x << ", " << y;
                }
            }
        }
    }
}

TEST_F(CompositeStageDepth, WithoutTheSpecialisationNoDepthIsRead) {
    const auto splats = TwoLayers();
    const auto lists = BuildTileLists(splats, TileGrid::ForImage(kWidth, kHeight), {});
    gpu::CompositeStageRunInputs in = ToCompositeStageInputs(splats, lists, kWidth, kHeight);
    const auto without = Run(in);
    // A texture that would hide everything (mesh at z = 1), bound but not tested.
    in.scene_depth.assign(size_t(kWidth) * kHeight, kNear / 1.0f);
    in.scene_near = kNear;
    in.scene_depth_unused = true;
    const auto bound_unused = Run(in);
    EXPECT_EQ(without.color, bound_unused.color);
    EXPECT_EQ(without.depth, bound_unused.depth);
    // And tested, it hides everything.
    in.scene_depth_unused = false;
    const auto tested = Run(in);
    for (float a : tested.alpha) ASSERT_EQ(a, 0.f);
}

TEST_F(CompositeStageDepth, MergeTakesTheNearerDepth) {
    // A splat (opacity 0.9, sigma 4 px, z = 3) centred at (8, 12); a mesh at z = 5 on rows
    // 0..11.
    const std::vector<ProjectedSplat> splats{
        MakeSplat(8.0, 12.0, 3.0, 4.0, 0.9, {1.0, 1.0, 1.0}, kWidth, kHeight)};
    const auto lists = BuildTileLists(splats, TileGrid::ForImage(kWidth, kHeight), {});
    gpu::CompositeStageRunInputs in = ToCompositeStageInputs(splats, lists, kWidth, kHeight);
    in.scene_depth.assign(size_t(kWidth) * kHeight, 0.f);
    for (int y = 0; y < 12; ++y) {
        for (int x = 0; x < kWidth; ++x) in.scene_depth[size_t(y) * kWidth + x] = kNear / 5.0f;
    }
    in.scene_near = kNear;
    in.depth_merge = true;
    in.merge.near = 1.0f;
    in.merge.far = 11.0f;
    in.merge.min_alpha = 0.5f;
    const auto out = Run(in);
    const auto at = [&](int x, int y) { return size_t(y) * kWidth + x; };
    const auto normalized = [&](float z) {
        return static_cast<uint16_t>(std::lround((z - 1.0f) / 10.0f * 65535.0f));
    };
    // Splat centre on a mesh-free row: the splat's depth, 3.
    EXPECT_NEAR(out.merged_linear[at(8, 12)], 3.0f, 1e-6);
    EXPECT_EQ(out.merged_normalized[at(8, 12)], normalized(3.0f));
    // Splat in front of the mesh with alpha 0.9 exp(-4 / 32) = 0.79 >= 0.5: the splat wins.
    EXPECT_NEAR(out.alpha[at(8, 10)], 0.9 * std::exp(-4.0 / 32.0), 1e-6);
    EXPECT_NEAR(out.merged_linear[at(8, 10)], 3.0f, 1e-6);
    // Over the mesh with alpha 0.9 exp(-64 / 32) = 0.12 < min_alpha: the mesh, 5.
    EXPECT_NEAR(out.merged_linear[at(8, 4)], 5.0f, 1e-6);
    // Mesh only (top right): 5.
    EXPECT_NEAR(out.merged_linear[at(35, 2)], 5.0f, 1e-6);
    EXPECT_EQ(out.merged_normalized[at(35, 2)], normalized(5.0f));
    // Neither (bottom right): 0 and 65535.
    EXPECT_EQ(out.merged_linear[at(35, 20)], 0.f);
    EXPECT_EQ(out.merged_normalized[at(35, 20)], 65535);
    // A faint splat edge (0 < alpha < 0.5) below the mesh rows does not count.
    bool checked_faint = false;
    for (int x = 0; x < kWidth && !checked_faint; ++x) {
        const float a = out.alpha[at(x, 20)];
        if (a > 0.f && a < 0.5f) {
            EXPECT_EQ(out.merged_linear[at(x, 20)], 0.f);
            EXPECT_EQ(out.merged_normalized[at(x, 20)], 65535);
            checked_faint = true;
        }
    }
    EXPECT_TRUE(checked_faint);
    EXPECT_GE(out.merge_ms, 0.0);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
