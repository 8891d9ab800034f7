// Composite stage (composite, scene-depth test, depth merge) on analytic splats, in isolation from
// Geometry stage: the inputs are the CPU reference's tile lists (CompositeStageTestUtil.h).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "CompositeStageTestUtil.h"
#include "VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace {

using rendering::cpu::BuildTileLists;
using rendering::cpu::ProjectedSplat;
using rendering::cpu::TileGrid;

// Analytic cases are a handful of float32 operations per splat away from the double
// reference: measured <= 1.2e-7 (lavapipe) on these images, so 1e-6 leaves margin for
// another GPU's exp() (NVIDIA: ex2.approx, a few ulp) without hiding a rule difference,
// which shows as >= 1/255.
constexpr double kAnalyticTolerance = 1e-6;

class CompositeStageComposite : public VulkanTest {
protected:
    gpu::CompositeStageReadback Run(const gpu::CompositeStageRunInputs& in) {
        gpu::GaussianCompositeStageRunner runner(Context());
        return runner.Run(in);
    }

    // Composites `splats` on the GPU and on the CPU and checks colour, expected depth, alpha
    // and median depth agree within `tolerance`.
    gpu::CompositeStageReadback RunAndCompare(const std::vector<ProjectedSplat>& splats, int width,
                                              int height,
                                              const rendering::RenderConfig& config = {},
                                              double tolerance = kAnalyticTolerance) {
        const auto lists = BuildTileLists(splats, TileGrid::ForImage(width, height), config);
        gpu::CompositeStageRunInputs in = ToCompositeStageInputs(splats, lists, width, height);
        in.background = {float(config.background[0]), float(config.background[1]),
                         float(config.background[2])};
        const gpu::CompositeStageReadback gpu_out = Run(in);
        const auto ref = ReferenceComposite(splats, lists, width, height, config);
        EXPECT_LE(CompareImage(gpu_out.color, ref.color).max_abs, tolerance) << "colour";
        EXPECT_LE(CompareImage(gpu_out.depth, ref.depth_expected).max_abs, tolerance * 10)
            << "expected depth (view z up to 10)";
        std::vector<float> ref_alpha(size_t(width) * height);
        for (size_t i = 0; i < ref_alpha.size(); ++i) {
            ref_alpha[i] = ref.color.Data<float>()[4 * i + 3];
        }
        EXPECT_LE(CompareValues(gpu_out.alpha.data(), ref_alpha.data(), ref_alpha.size()).max_abs,
                  tolerance)
            << "alpha";
        EXPECT_LE(CompareImage(gpu_out.median_depth, ref.depth_median).max_abs, tolerance * 10)
            << "median depth";
        return gpu_out;
    }
};

const float* Pixel(const gpu::CompositeStageReadback& out, int width, int x, int y) {
    return &out.color[(size_t(y) * width + x) * 4];
}

TEST_F(CompositeStageComposite, SingleSplatHeadOn) {
    const std::vector<ProjectedSplat> splats{
        MakeSplat(7.0, 9.0, 2.0, 3.0, 0.8, {1.0, 0.5, 0.25}, 16, 16)};
    const auto out = RunAndCompare(splats, 16, 16);
    // Pixel (7, 9) is evaluated at (7, 9): the centre, alpha = opacity.
    EXPECT_NEAR(Pixel(out, 16, 7, 9)[3], 0.8f, 1e-7);
    EXPECT_NEAR(Pixel(out, 16, 7, 9)[0], 0.8f, 1e-7);
    EXPECT_NEAR(out.depth[9 * 16 + 7], 2.0f, 1e-6);
    EXPECT_EQ(out.median_depth[9 * 16 + 7], 2.0f);  // alpha 0.8 >= 0.5 at the first splat
}

TEST_F(CompositeStageComposite, AlphaClampsAt099) {
    const std::vector<ProjectedSplat> splats{
        MakeSplat(8.0, 8.0, 1.0, 2.0, 1.0, {1.0, 1.0, 1.0}, 16, 16)};
    const auto out = RunAndCompare(splats, 16, 16);
    EXPECT_EQ(Pixel(out, 16, 8, 8)[3], 0.99f);  // 1 - T = 1 - (1 - 0.99f), exact in float
}

TEST_F(CompositeStageComposite, AlphaBelowOneOver255IsSkipped) {
    // Alpha at the centre is the opacity: 0.0039 < 1/255 = 0.0039216 is skipped everywhere,
    // 0.0040 contributes at the centre pixel only (exp(-0.5 / 4) * 0.004 < 1/255 next door).
    for (const double opacity : {0.0039, 0.0040}) {
        const std::vector<ProjectedSplat> splats{
            MakeSplat(5.0, 5.0, 1.0, 2.0, opacity, {1.0, 1.0, 1.0}, 16, 16)};
        const auto out = RunAndCompare(splats, 16, 16);
        int covered = 0;
        for (float a : out.alpha) covered += a > 0.f;
        EXPECT_EQ(covered, opacity < 1.0 / 255.0 ? 0 : 1) << "opacity " << opacity;
    }
}

TEST_F(CompositeStageComposite, TransmittanceStopsBeforeBlending) {
    // Opacity 0.95 at the centre: T = 0.05, 0.0025, 1.25e-4, then 6.25e-6 < 1e-4, so the
    // fourth splat is NOT blended there (and neither is anything behind it).
    std::vector<ProjectedSplat> splats;
    for (int i = 0; i < 3; ++i) {
        splats.push_back(MakeSplat(8.0, 8.0, 1.0 + i, 2.0, 0.95, {1.0, 0.0, 0.0}, 16, 16));
    }
    splats.push_back(MakeSplat(8.0, 8.0, 4.0, 2.0, 0.95, {0.0, 0.0, 1.0}, 16, 16));
    splats.push_back(MakeSplat(8.0, 8.0, 5.0, 2.0, 0.5, {0.0, 1.0, 0.0}, 16, 16));
    const auto out = RunAndCompare(splats, 16, 16);
    const float* centre = Pixel(out, 16, 8, 8);
    EXPECT_EQ(centre[1], 0.f);
    EXPECT_EQ(centre[2], 0.f);
    EXPECT_NEAR(centre[3], 1.0 - 0.05 * 0.05 * 0.05, 1e-6);
    // Stacks of 0.99-clamped splats: after one, T = 1 - 0.99f; the second would leave
    // 9.99998e-5 < 1e-4f, so only the first counts.
    std::vector<ProjectedSplat> opaque;
    for (int i = 0; i < 8; ++i) {
        opaque.push_back(
            MakeSplat(8.0, 8.0, 1.0 + i, 2.0, 1.0, {i == 0 ? 1.0 : 0.0, 1.0, 0.0}, 16, 16));
    }
    const auto out2 = RunAndCompare(opaque, 16, 16);
    EXPECT_EQ(Pixel(out2, 16, 8, 8)[3], 0.99f);
    EXPECT_NEAR(Pixel(out2, 16, 8, 8)[1], 0.99f, 1e-7);
}

TEST_F(CompositeStageComposite, BackgroundRule) {
    rendering::RenderConfig config;
    config.background = Eigen::Vector3d(0.2, 0.4, 0.6);
    const std::vector<ProjectedSplat> splats{
        MakeSplat(20.0, 10.0, 3.0, 2.0, 0.5, {1.0, 0.0, 0.0}, 40, 24)};
    const auto out = RunAndCompare(splats, 40, 24, config);
    // Far from the splat: exactly the background, alpha 0, depth 0.
    EXPECT_EQ(Pixel(out, 40, 0, 23)[0], 0.2f);
    EXPECT_EQ(Pixel(out, 40, 0, 23)[2], 0.6f);
    EXPECT_EQ(Pixel(out, 40, 0, 23)[3], 0.f);
    EXPECT_EQ(out.depth[23 * 40], 0.f);
    // Centre: C + T * bg with alpha 0.5.
    EXPECT_NEAR(Pixel(out, 40, 20, 10)[0], 0.5f + 0.5f * 0.2f, 1e-7);
    EXPECT_NEAR(Pixel(out, 40, 20, 10)[1], 0.5f * 0.4f, 1e-7);
}

// Many overlapping splats over several tiles and batches (> 256 per tile), at sizes that are
// not multiples of 16, tiny, very wide and very tall: the GPU must match the reference
// everywhere, whatever the work-stealing grid.
TEST_F(CompositeStageComposite, ShapesAndBatches) {
    struct Size {
        int width, height;
    };
    for (const Size size : {Size{1, 1}, Size{17, 33}, Size{1000, 3}, Size{2, 700}, Size{48, 48}}) {
        std::vector<ProjectedSplat> splats;
        uint32_t state = 12345u;
        const auto random = [&state]() {
            state = state * 1664525u + 1013904223u;
            return double(state >> 8) / double(1u << 24);
        };
        const int count = size.width * size.height > 2000 ? 700 : 300;
        for (int i = 0; i < count; ++i) {
            splats.push_back(MakeSplat(random() * size.width, random() * size.height,
                                       0.5 + 10.0 * random(), 0.5 + 6.0 * random(),
                                       0.05 + 0.9 * random(), {random(), random(), random()},
                                       size.width, size.height));
        }
        SCOPED_TRACE(std::to_string(size.width) + "x" + std::to_string(size.height));
        // Up to ~100 blended splats per pixel accumulate float32 rounding: measured <= 4.6e-6
        // (colour and alpha, lavapipe), 1e-5 allowed (still 400x below 1/255).
        RunAndCompare(splats, size.width, size.height, {}, 1e-5);
        const auto lists = BuildTileLists(splats, TileGrid::ForImage(size.width, size.height), {});
        gpu::CompositeStageRunInputs in =
            ToCompositeStageInputs(splats, lists, size.width, size.height);
        const auto many = Run(in);
        // One workgroup steals every tile in turn; three interleave their claims, each
        // holding the claim of its next tile while it composites the current one.
        for (const uint32_t workgroups : {1u, 3u}) {
            in.max_workgroups = workgroups;
            const auto few = Run(in);
            EXPECT_EQ(many.color, few.color) << workgroups << " workgroups";
            EXPECT_EQ(many.depth, few.depth) << workgroups << " workgroups";
        }
    }
}

// One tile with more than 65535 entries: 100,000 splats below the 1/255 alpha threshold, then
// one visible splat behind them. The GPU must walk the whole list (llvmpipe stops any loop of
// an invocation after 65535 back-edges in total; the composite unrolls its blending loop).
TEST_F(CompositeStageComposite, DenseTileReachesItsLastEntry) {
    std::vector<ProjectedSplat> splats;
    for (int i = 0; i < 100000; ++i) {
        splats.push_back(MakeSplat(8.0, 8.0, 1.0 + i * 1e-5, 3.0, 0.003, {1.0, 0.0, 0.0}, 16, 16));
    }
    splats.push_back(MakeSplat(8.0, 8.0, 5.0, 3.0, 0.5, {0.0, 1.0, 0.0}, 16, 16));
    const auto out = RunAndCompare(splats, 16, 16);
    EXPECT_NEAR(Pixel(out, 16, 8, 8)[1], 0.5f, 1e-7);
    EXPECT_EQ(Pixel(out, 16, 8, 8)[0], 0.f);
    std::cout << "[ composite stage ] 100,001 entries in one tile: composite " << out.composite_ms
              << " ms GPU\n";
}

TEST_F(CompositeStageComposite, EmptyEntryListGivesBackground) {
    gpu::CompositeStageRunInputs in;
    in.width = 35;
    in.height = 20;
    in.background = {0.25f, 0.5f, 1.0f};
    const auto out = Run(in);
    for (size_t i = 0; i < size_t(35 * 20); ++i) {
        ASSERT_EQ(out.color[4 * i + 0], 0.25f);
        ASSERT_EQ(out.color[4 * i + 2], 1.0f);
        ASSERT_EQ(out.color[4 * i + 3], 0.f);
        ASSERT_EQ(out.depth[i], 0.f);
        ASSERT_EQ(out.alpha[i], 0.f);
    }
}

TEST_F(CompositeStageComposite, Rgba16fIsTheRgba32fResultRounded) {
    std::vector<ProjectedSplat> splats;
    for (int i = 0; i < 40; ++i) {
        splats.push_back(MakeSplat(3.0 + i, 2.0 + 0.5 * i, 1.0 + 0.1 * i, 2.5, 0.6,
                                   {0.1 * (i % 10), 0.5, 1.2}, 48, 32));
    }
    const auto lists = BuildTileLists(splats, TileGrid::ForImage(48, 32), {});
    gpu::CompositeStageRunInputs in = ToCompositeStageInputs(splats, lists, 48, 32);
    const auto full = Run(in);
    in.color_format = gpu::CompositeColorFormat::kRgba16f;
    const auto half = Run(in);
    ASSERT_EQ(full.color.size(), half.color.size());
    for (size_t i = 0; i < full.color.size(); ++i) {
        // Half has 11 significant bits. Vulkan lets the float -> half conversion of a
        // storage-image write round to nearest (2^-11 relative) or toward zero (2^-10,
        // what lavapipe does: 0.604312 is stored as 0.604004).
        ASSERT_NEAR(half.color[i], full.color[i], std::abs(full.color[i]) * 0x1p-10 + 1e-7) << i;
    }
    EXPECT_EQ(full.depth, half.depth);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
