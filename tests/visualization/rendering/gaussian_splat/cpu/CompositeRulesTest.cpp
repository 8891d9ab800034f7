// Analytic checks of the composite stage: falloff, the 0.99 clamp, the 1/255 skip, the
// T < 1e-4 stop, depth order and ties, the depth outputs and the background rule.
// Expected values are closed-form in double; the images are float32, so tolerances are
// a few float32 ulps of values <= 1 (2^-24 ~ 6e-8): measured differences are <= 6e-8.
#include <gtest/gtest.h>

#include <cmath>

#include "SplatTestScene.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"

namespace open3d {
namespace tests {

using visualization::rendering::RenderConfig;
using visualization::rendering::RenderOutput;
using visualization::rendering::cpu::RenderReference;

constexpr double kImageTol = 2e-7;

double Px(const RenderOutput& out, int x, int y, int c) { return out.color.At<float>(y, x, c); }

TEST(CpuComposite, HeadOnSplatCentreAndGaussianFalloff) {
    TestSplat s;
    s.position = {0, 0, 5};
    s.scale = {0.075, 0.075, 0.075};
    s.opacity = 0.8;
    s.color = {0.9, 0.4, 0.2};
    const RenderOutput out = RenderReference(MakeCloud({s}), MakeTestCamera());
    const double op = StoredOpacity(0.8);
    // Centre pixel (32, 32) is evaluated exactly at the mean: alpha = opacity.
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(Px(out, 32, 32, c), op * StoredColor(s.color[c]), kImageTol);
    EXPECT_NEAR(Px(out, 32, 32, 3), op, kImageTol);
    // Falloff with the +0.3 dilation, pixel (x, y) evaluated at (x, y) (not x + 0.5).
    const double sigma2 = std::pow(100.0 * double(0.075f) / 5.0, 2) + 0.3;
    int checked = 0;
    for (int dy = -8; dy <= 8; ++dy) {
        for (int dx = -8; dx <= 8; ++dx) {
            double alpha =
                std::min(double(0.99f), op * std::exp(-0.5 * (dx * dx + dy * dy) / sigma2));
            if (alpha < double(1.0f / 255.0f)) alpha = 0.0;
            // All these pixels lie in tiles 1..2 of the splat's rectangle (radius 5 px).
            EXPECT_NEAR(Px(out, 32 + dx, 32 + dy, 3), alpha, kImageTol) << dx << "," << dy;
            ++checked;
        }
    }
    EXPECT_EQ(checked, 289);
    // Far away: untouched.
    EXPECT_EQ(Px(out, 0, 0, 3), 0.0);
}

TEST(CpuComposite, AlphaClampAt099) {
    TestSplat s;
    s.opacity = 0.99999;  // opacity * exp(0) > 0.99 at the centre
    s.color = {1.0, 0.5, 0.25};
    const RenderOutput out = RenderReference(MakeCloud({s}), MakeTestCamera());
    EXPECT_EQ(Px(out, 32, 32, 3), 0.99f);  // float(1 - (1 - double(0.99f)))
    EXPECT_NEAR(Px(out, 32, 32, 0), double(0.99f) * StoredColor(1.0), kImageTol);
}

TEST(CpuComposite, SkipBelowOneOver255) {
    TestSplat s;
    RenderConfig config;
    config.background = {0.2, 0.3, 0.4};
    // 0.1% either side of 1/255: far more than the 1e-7 float logit rounding, close enough
    // that a threshold of 1/256 fails the test.
    s.opacity = 0.999 / 255.0;  // centre alpha below 1/255: skipped, pixel is background
    RenderOutput out = RenderReference(MakeCloud({s}), MakeTestCamera(), config);
    EXPECT_EQ(Px(out, 32, 32, 3), 0.0);
    EXPECT_EQ(Px(out, 32, 32, 0), 0.2f);
    s.opacity = 1.001 / 255.0;  // just above: blended
    out = RenderReference(MakeCloud({s}), MakeTestCamera(), config);
    const double a = StoredOpacity(1.001 / 255.0);
    EXPECT_NEAR(Px(out, 32, 32, 3), a, kImageTol);
    // Background rule: rgb = C + T * background, alpha = 1 - T.
    EXPECT_NEAR(Px(out, 32, 32, 0), a * StoredColor(0.5) + (1.0 - a) * 0.2, kImageTol);
}

TEST(CpuComposite, StopsBeforeBlendingWhenTransmittanceFallsBelow1e4) {
    // Three opaque splats (alpha clamped to 0.99f) front to back: red, green, blue.
    TestSplat red, green, blue;
    red.position = {0, 0, 2};
    green.position = {0, 0, 3};
    blue.position = {0, 0, 4};
    red.color = {1, 0, 0};
    green.color = {0, 1, 0};
    blue.color = {0, 0, 1};
    for (TestSplat* s : {&red, &green, &blue}) s->opacity = 0.999999;
    // After red T = 1 - 0.99f = 0.0099999905; green would leave T = 9.99998e-5, which is
    // below 1e-4f = 9.99999975e-5: green is NOT blended (nor blue).
    RenderOutput out = RenderReference(MakeCloud({blue, green, red}), MakeTestCamera());
    EXPECT_NEAR(Px(out, 32, 32, 0), double(0.99f) * StoredColor(1.0), kImageTol);
    EXPECT_NEAR(Px(out, 32, 32, 1), 0.99 * (StoredColor(0.0)), 1e-6);  // f_dc rounding only
    EXPECT_EQ(Px(out, 32, 32, 3), 0.99f);

    // A softer front splat (0.9) leaves T = 0.1: green (T -> 0.001) is blended, blue
    // (T -> 1e-5) is not.
    red.opacity = 0.9;
    out = RenderReference(MakeCloud({blue, green, red}), MakeTestCamera());
    const double a1 = StoredOpacity(0.9);
    const double a2 = double(0.99f);
    const double t2 = (1 - a1) * (1 - a2);
    EXPECT_NEAR(Px(out, 32, 32, 3), 1.0 - t2, kImageTol);
    EXPECT_NEAR(Px(out, 32, 32, 1), a1 * StoredColor(0.0) + (1 - a1) * a2 * StoredColor(1.0),
                kImageTol);
    EXPECT_NEAR(Px(out, 32, 32, 2), a1 * StoredColor(0.0) + (1 - a1) * a2 * StoredColor(0.0),
                kImageTol);
}

TEST(CpuComposite, DepthOrderAndIndexTieBreak) {
    TestSplat a, b;
    a.color = {1, 0, 0};
    b.color = {0, 0, 1};
    a.opacity = b.opacity = 0.5;
    // Same depth: the lower splat index is in front.
    RenderOutput out = RenderReference(MakeCloud({a, b}), MakeTestCamera());
    const double o = StoredOpacity(0.5);
    EXPECT_NEAR(Px(out, 32, 32, 0), o * StoredColor(1.0) + (1 - o) * o * StoredColor(0.0),
                kImageTol);
    out = RenderReference(MakeCloud({b, a}), MakeTestCamera());
    EXPECT_NEAR(Px(out, 32, 32, 2), o * StoredColor(1.0) + (1 - o) * o * StoredColor(0.0),
                kImageTol);
    // Depth wins over index: a behind b although a has the lower index.
    a.position.z() = 6.0;
    out = RenderReference(MakeCloud({a, b}), MakeTestCamera());
    EXPECT_GT(Px(out, 32, 32, 2), Px(out, 32, 32, 0));
}

TEST(CpuComposite, ExpectedAndMedianDepth) {
    TestSplat front, back;
    front.position = {0, 0, 2};
    back.position = {0, 0, 4};
    front.opacity = 0.3;
    back.opacity = 0.6;
    const RenderOutput out = RenderReference(MakeCloud({front, back}), MakeTestCamera());
    const double a1 = StoredOpacity(0.3), a2 = StoredOpacity(0.6);
    const double w1 = a1, w2 = (1 - a1) * a2;
    EXPECT_NEAR(out.depth_expected.At<float>(32, 32), (2 * w1 + 4 * w2) / (w1 + w2), 1e-6);
    // 1 - T = 0.3 after the front splat, 0.72 after the back one: the median is 4.
    EXPECT_EQ(out.depth_median.At<float>(32, 32), 4.0f);
    EXPECT_EQ(out.depth_expected.At<float>(0, 0), 0.0f);  // nothing there
    EXPECT_EQ(out.depth_median.At<float>(0, 0), 0.0f);
}

TEST(CpuComposite, GuardBandSplatReachesIntoTheImageEdge) {
    // Centre at pixel x = -20 (off-screen): its clamped-Jacobian footprint covers column 0.
    TestSplat s;
    s.position = {-0.52 * 5.0, 0, 5};
    s.scale = {0.45, 0.45, 0.45};
    s.opacity = 0.9;
    const RenderOutput out = RenderReference(MakeCloud({s}), MakeTestCamera());
    // Clamped at the band's left edge: its centre is the image's, (31.5 - cx) / fx.
    const double edge = (31.5 - 32.0) / 100.0 - 1.3 * 64.0 / 200.0;
    const double k2 = std::pow(100.0 * double(0.45f) / 5.0, 2);
    const double cov_a = k2 * (1 + edge * edge) + 0.3, cov_c = k2 + 0.3;
    const double cx = 32.0 + 100.0 * double(float(-2.6)) / 5.0;
    for (int y : {32, 40}) {
        const double dx = cx - 0.0, dy = 0.0 - y + 32.0;
        const double alpha =
            StoredOpacity(0.9) * std::exp(-0.5 * (dx * dx / cov_a + dy * dy / cov_c));
        EXPECT_NEAR(Px(out, 0, y, 3), alpha, kImageTol) << "row " << y;
    }
}

TEST(CpuComposite, SceneDepthOccludesSplatsBehindIt) {
    TestSplat s;
    s.opacity = 0.8;
    visualization::rendering::cpu::CpuBackend backend;
    backend.SetScene(MakeCloud({s}));
    backend.RenderGeometryStage(MakeTestCamera(), RenderConfig{});
    t::geometry::Image scene(64, 64, 1, core::Dtype::Float32);
    for (int64_t i = 0; i < 64 * 64; ++i) scene.Data<float>()[i] = 1e30f;
    scene.At<float>(32, 32) = 4.0f;  // a mesh at z = 4 in front of the splat (z = 5)
    RenderOutput out;
    backend.RenderCompositeStage(out, {&scene});
    EXPECT_EQ(Px(out, 32, 32, 3), 0.0);
    EXPECT_GT(Px(out, 33, 32, 3), 0.5);
}

}  // namespace tests
}  // namespace open3d
