// The depths that order splats (shaders/GaussianSplatShared.h): the fused multiply-add
// built from plain float operations against the C library's fmaf, the original rasterizer's
// view z against hand-computed float32 values, and the order the CPU reference gives two
// splats closer than one float32 step.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "GaussianSplatShared.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"
#include "visualization/rendering/gaussian_splat/cpu/SplatTestScene.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
namespace shader = visualization::rendering::shader;

// std::fma is the correctly rounded fused operation (C11 fmaf).
float Fused(float a, float b, float c) { return std::fma(a, b, c); }

// a * b + c rounded twice; volatile keeps the product's rounding whatever the compiler does.
float Unfused(float a, float b, float c) {
    volatile float p = a * b;
    return p + c;
}

float LogUniform(std::mt19937& rng, float lo_exp, float hi_exp) {
    std::uniform_real_distribution<float> e(lo_exp, hi_exp);
    std::bernoulli_distribution negative(0.5);
    const float v = std::exp2(e(rng));
    return negative(rng) ? -v : v;
}

TEST(SortDepth, ExactFmaEqualsTheFusedOperation) {
    std::mt19937 rng(12345);
    int64_t cases = 0, unfused_differs = 0;
    auto check = [&](float a, float b, float c) {
        const float want = Fused(a, b, c);
        const float got = shader::ExactFma(a, b, c);
        ASSERT_EQ(std::bit_cast<uint32_t>(got), std::bit_cast<uint32_t>(want))
            << "ExactFma(" << a << ", " << b << ", " << c << ")";
        ++cases;
        if (Unfused(a, b, c) != want) ++unfused_differs;
    };
    std::uniform_int_distribution<int> small(-64, 64);
    for (int i = 0; i < 200000; ++i) {
        const float a = LogUniform(rng, -20, 20), b = LogUniform(rng, -20, 20);
        // Any addend, from far below to far above the product.
        check(a, b, LogUniform(rng, -45, 45));
        // The hard cases: c cancels the rounded product, leaving its rounding error, or sits a
        // few half-ulps of the product away, so the exact sum lands on or next to a midpoint.
        const float p = a * b;
        check(a, b, -p);
        const float half_ulp = std::abs(std::nextafter(p, 2 * p) - p) / 2;
        check(a, b, -p + small(rng) * half_ulp);
        check(a, b, small(rng) * half_ulp);
        check(a, b, -std::nextafter(p, 0.0f));
    }
    // Products of two 12-bit halves hit exact midpoints: (1 + 2^-12)^2 = 1 + 2^-11 + 2^-24.
    const float k = 1.0f + std::ldexp(1.0f, -12);
    check(k, k, 0.0f);
    check(k, k, -1.0f);
    check(k, -k, std::ldexp(1.0f, -30));
    // The random hard cases must be hard: rounding twice gets many of them wrong, so a plain
    // a * b + c inside ExactFma would fail above (measured: 666,162 of 1,000,003 cases).
    std::printf("[sort depth] a * b + c rounded twice differs from fma in %lld of %lld cases\n",
                static_cast<long long>(unfused_differs), static_cast<long long>(cases));
    EXPECT_GT(unfused_differs, cases / 3) << unfused_differs << " of " << cases;
}

TEST(SortDepth, ReferenceViewDepthIsTheOriginalsFusedExpression) {
    // By hand: m2 x = (1 + 2^-12)^2 = 1 + 2^-11 + 2^-24 exactly, m6 y = -(1 + 2^-11), so the
    // first fused operation leaves 2^-24; rounding the product first would leave 0.
    const float k = 1.0f + std::ldexp(1.0f, -12);
    const float m6 = -(1.0f + std::ldexp(1.0f, -11));
    EXPECT_EQ(shader::ReferenceViewDepth(k, m6, 0.0f, 0.0f, k, 1.0f, 0.0f), std::ldexp(1.0f, -24));
    // Then m10 z is fused into that sum: 2^-24 + 3 * 2^-23 = 7 * 2^-24 exactly.
    EXPECT_EQ(shader::ReferenceViewDepth(k, m6, 3.0f, 0.0f, k, 1.0f, std::ldexp(1.0f, -23)),
              std::ldexp(7.0f, -24));
    // Random rows and positions against fma(m10, z, fma(m2, x, m6 y)) + m14 spelled out.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), pos(-20.0f, 20.0f);
    for (int i = 0; i < 100000; ++i) {
        const float m2 = u(rng), m6 = u(rng), m10 = u(rng), m14 = 10 * u(rng);
        const float x = pos(rng), y = pos(rng), z = pos(rng);
        volatile float m6y = m6 * y;
        const float want = std::fma(m10, z, std::fma(m2, x, m6y)) + m14;
        ASSERT_EQ(shader::ReferenceViewDepth(m2, m6, m10, m14, x, y, z), want) << i;
    }
}

// A camera looking along a skewed direction from away from the origin, so both depth
// formulas round differently (the identity camera would make both equal z exactly).
const Eigen::Vector3d look_center(0.2, 0.1, 0.3);

camera::PinholeCamera SkewedCamera() {
    camera::LookAtCamera look;
    look.eye = Eigen::Vector3d(1.3, -0.7, -4.1);
    look.center = look_center;
    look.up = Eigen::Vector3d(0.1, -1.0, 0.05);
    look.vertical_fov_deg = 50.0;
    return camera::PinholeCamera::FromLookAt(look, 64, 64);
}

TEST(SortDepth, NearTiedSplatsFollowTheChosenKeyTiesByIndex) {
    const camera::PinholeCamera cam = SkewedCamera();
    const ReferenceDepthRow m = GetReferenceDepthRow(cam);
    const CameraCenterSplit c = SplitCameraCenter(cam);
    const Eigen::Matrix3d r = cam.GetRotation();
    auto reference_key = [&](const float* p) {
        return shader::ReferenceViewDepth(m.m2, m.m6, m.m10, m.m14, p[0], p[1], p[2]);
    };
    auto relative_key = [&](const float* p) {
        float rel[3];
        for (int i = 0; i < 3; ++i) rel[i] = shader::CameraRelative(p[i], c.high[i], c.low[i]);
        return shader::SortDepth(float(r(2, 0)), float(r(2, 1)), float(r(2, 2)), rel[0], rel[1],
                                 rel[2]);
    };
    // Find, near the view's centre, two positions a few dozen float32 steps of a coordinate
    // apart (depths within a step or two of each other) whose keys disagree: a in front of
    // b by the original's key, b in front of (or tied with) a by the camera-relative one.
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> around(-0.5f, 0.5f);
    std::uniform_int_distribution<int> step(-40, 40);
    float a[3], b[3];
    bool found = false;
    for (int attempt = 0; attempt < 100000 && !found; ++attempt) {
        for (int i = 0; i < 3; ++i) {
            a[i] = float(look_center[i]) + around(rng);
            b[i] = std::bit_cast<float>(std::bit_cast<int32_t>(a[i]) + step(rng));
        }
        found = reference_key(a) < reference_key(b) && relative_key(b) <= relative_key(a);
    }
    ASSERT_TRUE(found) << "no pair whose two keys disagree";

    // Splat 0 at b, splat 1 at a: the default order puts a (index 1) first, the
    // camera-relative order b (index 0, first on a tie).
    TestSplat sa, sb;
    sa.position = Eigen::Vector3d(a[0], a[1], a[2]);
    sb.position = Eigen::Vector3d(b[0], b[1], b[2]);
    const t::geometry::PointCloud cloud = MakeCloud({sb, sa});
    RenderConfig config;
    const auto reference = cpu::ProjectSplats(cloud, cam, config);
    EXPECT_EQ(reference[1].sort_depth, reference_key(a));
    EXPECT_EQ(cpu::SortVisibleByDepth(reference), (std::vector<uint32_t>{1, 0}));
    config.depth_order = DepthOrder::kCameraRelative;
    const auto relative = cpu::ProjectSplats(cloud, cam, config);
    EXPECT_EQ(relative[0].sort_depth, relative_key(b));
    EXPECT_EQ(cpu::SortVisibleByDepth(relative), (std::vector<uint32_t>{0, 1}));

    // Equal keys: the lower index first, whatever the order of the cloud.
    const t::geometry::PointCloud twins = MakeCloud({sa, sa});
    EXPECT_EQ(cpu::SortVisibleByDepth(cpu::ProjectSplats(twins, cam, {})),
              (std::vector<uint32_t>{0, 1}));
}

}  // namespace
}  // namespace tests
}  // namespace open3d
