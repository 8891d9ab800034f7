// Analytic checks of the projection stage (docs/DESIGN.md "Numerical rules"). Expected values are
// closed-form; tolerances cover double rounding only (the projection stays in double).
#include <gtest/gtest.h>

#include <cmath>

#include "SplatTestScene.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"

namespace open3d {
namespace tests {

using visualization::rendering::RenderConfig;
using namespace visualization::rendering::cpu;

// Projection is double throughout; measured differences to the closed forms are
// below 1e-12 relative, so 1e-9 is a loose bound that still catches any rule change.
constexpr double kTol = 1e-9;

TEST(CpuProjection, HeadOnIsotropicSplat) {
    TestSplat s;
    s.position = {0, 0, 5};
    s.scale = {0.075, 0.075, 0.075};  // 1.5 px sigma at fx = 100, z = 5
    s.opacity = 0.8;
    const auto splats = ProjectSplats(MakeCloud({s}), MakeTestCamera(), RenderConfig{});
    ASSERT_EQ(splats.size(), 1u);
    const ProjectedSplat& p = splats[0];
    ASSERT_TRUE(p.IsVisible());
    EXPECT_NEAR(p.x, 32.0, kTol);
    EXPECT_NEAR(p.y, 32.0, kTol);
    EXPECT_NEAR(p.depth, 5.0, kTol);
    const double sigma2 = std::pow(100.0 * double(0.075f) / 5.0, 2) + 0.3;  // + low-pass
    EXPECT_NEAR(p.cov_a, sigma2, kTol);
    EXPECT_NEAR(p.cov_c, sigma2, kTol);
    EXPECT_NEAR(p.cov_b, 0.0, kTol);
    EXPECT_NEAR(p.conic_a, 1.0 / sigma2, kTol);
    EXPECT_NEAR(p.conic_c, 1.0 / sigma2, kTol);
    // Equal eigenvalues: mid^2 - det = 0, so the 0.1 floor adds sqrt(0.1) to lambda_max.
    EXPECT_EQ(p.radius, static_cast<int>(std::ceil(3.0 * std::sqrt(sigma2 + std::sqrt(0.1)))));
    EXPECT_NEAR(p.opacity, StoredOpacity(0.8), kTol);
    // Tile rect: (int)((32 - r) / 16) .. (int)((32 + r + 15) / 16).
    EXPECT_EQ(p.rect_min_x, (32 - p.radius) / 16);
    EXPECT_EQ(p.rect_max_x, (32 + p.radius + 15) / 16);
}

TEST(CpuProjection, AnisotropicRotatedSplat) {
    // Scale 0.2 along x, 0.05 along y, rotated 90 degrees about z: the long axis becomes y.
    TestSplat s;
    s.position = {0, 0, 4};
    s.scale = {0.2, 0.05, 0.01};
    const double h = std::sqrt(0.5);
    s.rot = {h, 0, 0, h};
    const auto p = ProjectSplats(MakeCloud({s}), MakeTestCamera(), RenderConfig{})[0];
    const double k = 100.0 / 4.0;
    EXPECT_NEAR(p.cov_a, std::pow(k * double(0.05f), 2) + 0.3, 1e-7);
    EXPECT_NEAR(p.cov_c, std::pow(k * double(0.2f), 2) + 0.3, 1e-7);
    EXPECT_NEAR(p.cov_b, 0.0, 1e-7);  // float32 quaternion h: off-diagonal ~1e-8
    // Unequal eigenvalues: lambda_max = cov_c, no floor.
    EXPECT_EQ(p.radius, static_cast<int>(std::ceil(3.0 * std::sqrt(p.cov_c))));
}

TEST(CpuProjection, NearPlaneCull) {
    TestSplat near_splat, far_splat;
    near_splat.position = {0, 0, 0.199};
    far_splat.position = {0, 0, 0.201};
    const auto splats =
        ProjectSplats(MakeCloud({near_splat, far_splat}), MakeTestCamera(), RenderConfig{});
    EXPECT_EQ(splats[0].cull, CullReason::kNearPlane);
    EXPECT_TRUE(splats[1].IsVisible());
    RenderConfig config;
    config.near_plane = 0.5;  // a RenderConfig value, not a constant
    EXPECT_EQ(ProjectSplats(MakeCloud({far_splat}), MakeTestCamera(), config)[0].cull,
              CullReason::kNearPlane);
    TestSplat behind;
    behind.position = {0, 0, -3};
    EXPECT_EQ(ProjectSplats(MakeCloud({behind}), MakeTestCamera(), RenderConfig{})[0].cull,
              CullReason::kNearPlane);
}

TEST(CpuProjection, DeterminantZeroCull) {
    // After +0.3: [[1, 1], [1, 1]] has det exactly 0.
    EXPECT_TRUE(ComputeScreenEllipse(0.7, 1.0, 0.7, false).degenerate);
    const ScreenEllipse ok = ComputeScreenEllipse(0.7, 0.5, 0.7, false);
    EXPECT_FALSE(ok.degenerate);
    EXPECT_NEAR(ok.conic_a, 1.0 / 0.75, kTol);  // det = 1 - 0.25
    EXPECT_NEAR(ok.conic_b, -0.5 / 0.75, kTol);
    // lambda = 1 +- 0.5: radius ceil(3 sqrt(1.5)) = 4.
    EXPECT_EQ(ok.radius, 4);
}

TEST(CpuProjection, AntialiasOpacityFactor) {
    TestSplat s;
    s.position = {0, 0, 5};
    s.scale = {0.02, 0.02, 0.02};  // 0.4 px sigma: strong compensation
    s.opacity = 0.9;
    RenderConfig config;
    config.antialias = true;
    const auto p = ProjectSplats(MakeCloud({s}), MakeTestCamera(), config)[0];
    const double a = std::pow(100.0 * double(0.02f) / 5.0, 2);
    EXPECT_NEAR(p.opacity, StoredOpacity(0.9) * std::sqrt(a * a / ((a + 0.3) * (a + 0.3))), kTol);
    // The 2.5e-5 floor: a zero-size splat keeps opacity * sqrt(2.5e-5) = opacity * 0.005.
    s.scale = {0, 0, 0};
    const auto z = ProjectSplats(MakeCloud({s}), MakeTestCamera(), config)[0];
    EXPECT_NEAR(z.opacity, StoredOpacity(0.9) * 0.005, kTol);
}

TEST(CpuProjection, JacobianGuardBandClampsOffscreenSplats) {
    // Centre at pixel x = -20: X / Z = -0.52, beyond the guard band 1.3 * 64 / 200 = 0.416.
    TestSplat s;
    s.position = {-0.52 * 5.0, 0, 5};
    s.scale = {0.45, 0.45, 0.45};
    const auto p = ProjectSplats(MakeCloud({s}), MakeTestCamera(), RenderConfig{})[0];
    ASSERT_TRUE(p.IsVisible());
    EXPECT_NEAR(p.x, 32.0 + 100.0 * double(float(-0.52 * 5.0)) / 5.0, kTol);
    // The band is centred on the image: cx = 32 is half a pixel right of the centre 31.5.
    const double lim = 1.3 * 64.0 / (2.0 * 100.0), center = (31.5 - 32.0) / 100.0;
    const double k2 = std::pow(100.0 * double(0.45f) / 5.0, 2);
    // J row 0 = (f/z, 0, -f tx / z^2) with tx = (center - lim) z:
    // |row|^2 = (f/z)^2 (1 + (center - lim)^2).
    EXPECT_NEAR(p.cov_a, k2 * (1.0 + (center - lim) * (center - lim)) + 0.3, 1e-7);
    EXPECT_NEAR(p.cov_c, k2 + 0.3, 1e-7);
    // Inside the guard band nothing is clamped: X / Z = -0.3 gives (1 + 0.09).
    s.position = {-0.3 * 5.0, 0, 5};
    const auto q = ProjectSplats(MakeCloud({s}), MakeTestCamera(), RenderConfig{})[0];
    EXPECT_NEAR(q.cov_a, k2 * (1.0 + double(float(-1.5)) * float(-1.5) / 25.0) + 0.3, 1e-7);
}

TEST(CpuProjection, TheGuardBandFollowsAnOffCentrePrincipalPoint) {
    // A crop: the 64 x 64 camera's principal point at cx = -40, so the image spans
    // X / Z = 0.405 .. 1.035 and its centre is X / Z = 0.72, beyond the band of a band
    // centred on the axis (0.416). A splat at X / Z = 0.9 is inside the image: its Jacobian
    // is taken where it is, as in a wide view whose band reaches it.
    TestSplat s;
    s.position = {0.9 * 5.0, 0, 5};
    s.scale = {0.45, 0.45, 0.45};
    camera::PinholeCamera crop = MakeTestCamera();
    crop.cx = -40.0;
    const auto p = ProjectSplats(MakeCloud({s}), crop, RenderConfig{})[0];
    ASSERT_TRUE(p.IsVisible());
    const double x_over_z = double(float(0.9 * 5.0)) / 5.0;
    const double k2 = std::pow(100.0 * double(0.45f) / 5.0, 2);
    EXPECT_NEAR(p.cov_a, k2 * (1.0 + x_over_z * x_over_z) + 0.3, 1e-7);
    // The same splat in a view 4 times as wide (centred) projects alike.
    camera::PinholeCamera wide = MakeTestCamera(256, 64);
    wide.cx = 127.5;
    wide.cy = 32.0;
    const auto q = ProjectSplats(MakeCloud({s}), wide, RenderConfig{})[0];
    EXPECT_NEAR(p.cov_a, q.cov_a, 1e-9);
    EXPECT_NEAR(p.cov_b, q.cov_b, 1e-9);
    EXPECT_NEAR(p.cov_c, q.cov_c, 1e-9);
}

TEST(CpuProjection, OffscreenSplatWithoutTilesIsCulled) {
    TestSplat s;
    s.position = {-2.0 * 5.0, 0, 5};  // pixel x = -168, radius ~ 5 px
    s.scale = {0.01, 0.01, 0.01};
    EXPECT_EQ(ProjectSplats(MakeCloud({s}), MakeTestCamera(), RenderConfig{})[0].cull,
              CullReason::kNoTiles);
}

// Closed-form 3DGS SH (constants typed from the reference CUDA code) for direction d.
std::array<double, 3> ExpectedSH(int degree, const Eigen::Vector3d& color,
                                 const std::vector<double>& rest, Eigen::Vector3d d) {
    for (int i = 0; i < 3; ++i) d[i] = RoundToFloat(d[i]);  // positions are float32
    d.normalize();
    const double x = d.x(), y = d.y(), z = d.z();
    const double c1 = 0.4886025119029199;
    const double c2[5] = {1.0925484305920792, -1.0925484305920792, 0.31539156525252005,
                          -1.0925484305920792, 0.5462742152960396};
    const double c3[7] = {-0.5900435899266435, 2.890611442640554,   -0.4570457994644658,
                          0.3731763325901154,  -0.4570457994644658, 1.445305721320277,
                          -0.5900435899266435};
    const double basis[15] = {-c1 * y,
                              c1 * z,
                              -c1 * x,
                              c2[0] * x * y,
                              c2[1] * y * z,
                              c2[2] * (2 * z * z - x * x - y * y),
                              c2[3] * x * z,
                              c2[4] * (x * x - y * y),
                              c3[0] * y * (3 * x * x - y * y),
                              c3[1] * x * y * z,
                              c3[2] * y * (4 * z * z - x * x - y * y),
                              c3[3] * z * (2 * z * z - 3 * x * x - 3 * y * y),
                              c3[4] * x * (4 * z * z - x * x - y * y),
                              c3[5] * z * (x * x - y * y),
                              c3[6] * x * (x * x - 3 * y * y)};
    std::array<double, 3> out;
    const int nb = (degree + 1) * (degree + 1) - 1;
    for (int c = 0; c < 3; ++c) {
        double v = StoredColor(color[c]);
        for (int k = 0; k < nb; ++k) v += basis[k] * RoundToFloat(rest[k * 3 + c]);
        out[c] = std::max(0.0, v);
    }
    return out;
}

TEST(CpuProjection, SphericalHarmonicsDegrees1To3) {
    TestSplat s;
    s.position = {0.3, -0.4, 2.0};  // direction from the camera centre (origin)
    s.color = {0.4, 0.5, 0.6};
    for (int k = 0; k < 45; ++k) s.f_rest.push_back(0.05 * std::sin(1.7 * k + 0.3));
    for (int degree = 1; degree <= 3; ++degree) {
        const auto p = ProjectSplats(MakeCloud({s}, degree), MakeTestCamera(), RenderConfig{})[0];
        const auto e = ExpectedSH(degree, s.color, s.f_rest, s.position);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.color[c], e[c], 1e-12) << "degree " << degree;
    }
    // The sh_degree knob caps a degree-3 scene.
    RenderConfig config;
    config.sh_degree = 1;
    const auto p = ProjectSplats(MakeCloud({s}, 3), MakeTestCamera(), config)[0];
    const auto e = ExpectedSH(1, s.color, s.f_rest, s.position);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.color[c], e[c], 1e-12);
}

TEST(CpuProjection, ShDirectionUsesCameraCentreAndClampsBelowOnly) {
    // Camera moved to (0, 0, -3) and looking along +z: direction is mean - centre.
    camera::PinholeCamera cam = MakeTestCamera();
    cam.world_to_camera(2, 3) = 3.0;
    TestSplat s;
    s.position = {0.0, 1.0, 1.0};
    s.color = {0.1, 0.9, 1.4};                 // > 1 must stay > 1, < 0 results clamp to 0
    s.f_rest = {0, 0, 0, 0, 0, 0, 2.0, 0, 0};  // k = 2 (basis -C1 x), red only
    s.position.x() = 0.5;
    const auto p = ProjectSplats(MakeCloud({s}, 1), cam, RenderConfig{})[0];
    // Camera centre at (0, 0, -3); the direction starts from there.
    const auto e = ExpectedSH(1, s.color, s.f_rest,
                              s.position.cast<float>().cast<double>() + Eigen::Vector3d(0, 0, 3));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.color[c], e[c], 1e-12);
    EXPECT_EQ(p.color[0], 0.0);  // 0.1 - 2 C1 x < 0
    EXPECT_GT(p.color[2], 1.0);
}

}  // namespace tests
}  // namespace open3d
