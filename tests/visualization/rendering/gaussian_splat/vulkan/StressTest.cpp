// The numerical stress suite: scenes built in code at the edges of float32 (degenerate and
// huge splats, the near plane, the camera inside a splat, the guard band, depths up to 1e5,
// coordinates 1e5 from the origin, opacity logits of +-100, unnormalised and near-zero
// quaternions, SH coefficients of 1e4, 1x1 / 4096x2 / 8K images), each rendered by the CPU
// reference and the "vulkan" backend and compared. Every case checks: no NaN or Inf in any
// output of either renderer, no validation message (the fixture), no device loss (an
// exception fails the test), the same culled set and tile lists (geometry stage compared splat by
// splat), the same coverage and median depth per pixel, and colour / expected depth within
// a tolerance that the comment beside it justifies by the error measured on lavapipe (an
// H100 fits the same bounds; docs/perf/lavapipe.md and docs/perf/h100.md have both, and
// docs/accuracy.md "Numerical stress suite" the rules these cases hold the renderers to).
#include "StressFixture.h"

namespace open3d {
namespace tests {
namespace {

using namespace visualization::rendering;
using namespace stress;
using namespace stress_suite;

TEST_F(Stress, ScalesFrom1e8To1e4) {
    // Isotropic, flat (one axis 1e-8) and needle (two axes 1e-8) splats of scale 10^k,
    // k = -8..4, tilted; the huge ones sit far away or contain the camera (faint, so the
    // small ones stay visible through them).
    std::vector<RawSplat> splats;
    int index = 0;
    for (int k = -8; k <= 4; ++k) {
        const double s = std::pow(10.0, k);
        for (int shape = 0; shape < 3; ++shape, ++index) {
            RawSplat p;
            const double z = k <= 0 ? 4.0 + 0.1 * index : 3.0 * std::pow(10.0, k - 1) + 2.0;
            p.position =
                Eigen::Vector3d((index % 7 - 3) * 0.35 * z / 3, (index / 7 - 2) * 0.3 * z / 3, z);
            p.scale = shape == 0   ? Eigen::Vector3d(s, s, s)
                      : shape == 1 ? Eigen::Vector3d(s, s, 1e-8)
                                   : Eigen::Vector3d(s, 1e-8, 1e-8);
            p.rot = AxisAngle(0.4 + 0.7 * index, Eigen::Vector3d(1, 2, 3 - index % 5));
            p.logit = Logit(k >= 1 ? 0.15 : 0.8);
            p.f_dc = Eigen::Vector3d(0.2 * (index % 5), 0.9 - 0.1 * (index % 8), 0.3);
            splats.push_back(p);
        }
    }
    // Measured 131.9 dB, max 6.7e-6, depth 2.9e-5 relative: float32 rounding of the sub-pixel
    // needles' centres and conics (1 / 0.3 px^2 across); the expected depth mixes z = 4 with
    // z = 3002 in one pixel, which scales the weights' rounding by the depth ratio.
    const Bounds bounds = MakeBounds(120.0, 3e-5, 1e-4);
    RenderBoth("scales 1e-8..1e4", MakeRawCloud(splats), MakeCamera(kW, kH, kF), bounds);
}

TEST_F(Stress, ScalesPastTheFloatRangeAreCulledByBoth) {
    // Splats whose screen determinant passes the float32 range (docs/accuracy.md "Extremes"):
    // isotropic 1e30 and 1e10, flat 1e20, in front of the camera, among ordinary splats. Both
    // renderers cull them; before, the CPU drew the 1e30 splat over the whole frame and the
    // GPU counted it visible with no entry. (A needle of length 1e12 is not culled: its
    // determinant stays finite, and both draw it as the same clamped streak.)
    std::vector<RawSplat> ordinary;
    for (int i = 0; i < 12; ++i) {
        RawSplat p;
        p.position = Eigen::Vector3d((i % 4 - 1.5) * 0.9, (i / 4 - 1.0) * 0.8, 4.0 + 0.3 * i);
        p.scale = Eigen::Vector3d(0.2, 0.12, 0.05);
        p.rot = AxisAngle(0.3 * i, Eigen::Vector3d(1, 1, 0));
        p.logit = Logit(0.7);
        p.f_dc = Eigen::Vector3d(0.1 * (i % 5), 0.8 - 0.05 * i, 0.4);
        ordinary.push_back(p);
    }
    std::vector<RawSplat> with_monsters = ordinary;
    const double scales[][3] = {{1e30, 1e30, 1e30}, {1e20, 1e20, 1e-3}, {1e10, 1e10, 1e10}};
    for (int k = 0; k < 3; ++k) {
        RawSplat m;
        m.position = Eigen::Vector3d(0.3 * k - 0.3, 0.1, 5.0 + k);
        m.scale = Eigen::Vector3d(scales[k][0], scales[k][1], scales[k][2]);
        m.rot = AxisAngle(0.5 + k, Eigen::Vector3d(0, 1, 1));
        m.logit = Logit(0.5);
        with_monsters.insert(with_monsters.begin() + 4 * k, m);  // among the others
    }
    const camera::PinholeCamera cam = MakeCamera(kW, kH, kF);
    const t::geometry::PointCloud cloud = MakeRawCloud(with_monsters);
    // Measured on lavapipe: 144.1 dB, max 1.0e-6, depth 2.9e-7 (the ordinary splats alone).
    RenderBoth("scales 1e10..1e30", cloud, cam, MakeBounds(120.0, 3e-5, 1e-4));
    const t::geometry::PointCloud plain = MakeRawCloud(ordinary);
    const RenderOutput ref = cpu::RenderReference(cloud, cam, {});
    const RenderOutput ref_plain = cpu::RenderReference(plain, cam, {});
    EXPECT_EQ(ref.stats.num_visible, ref_plain.stats.num_visible);
    EXPECT_TRUE(ref.color.AsTensor() == ref_plain.color.AsTensor());
    auto backend = MakeBackend();
    backend->SetScene(cloud);
    const RenderOutput gpu = backend->Render(cam, {});
    backend->SetScene(plain);
    const RenderOutput gpu_plain = backend->Render(cam, {});
    EXPECT_EQ(gpu.stats.num_visible, gpu_plain.stats.num_visible);
    EXPECT_EQ(gpu.stats.num_tile_entries, gpu_plain.stats.num_tile_entries);
    EXPECT_TRUE(gpu.color.AsTensor() == gpu_plain.color.AsTensor());
}

TEST_F(Stress, HugeFlatSplatSeenEdgeOn) {
    // Discs of radius 1e4..10 (thickness 1e-8) whose planes contain the view axis, rolled
    // about it: (nearly) edge-on, the screen covariance is rank one and det(cov) cancels.
    std::vector<RawSplat> splats;
    for (int i = 0; i < 4; ++i) {
        RawSplat p;
        const double z = std::pow(10.0, i);
        p.position = Eigen::Vector3d(0.1 * z * (i - 1.5), 0.05 * z, z + 1);
        p.scale = Eigen::Vector3d(1e-8, std::pow(10.0, 4 - i), std::pow(10.0, 4 - i));
        p.rot = AxisAngle(0.5 + 0.3 * i, Eigen::Vector3d::UnitZ());  // roll about the view axis
        p.logit = Logit(0.7);
        p.f_dc = Eigen::Vector3d(0.9, 0.2 * i, 0.5);
        splats.push_back(p);
    }
    // Measured 143.6 dB, max 3.6e-7, depth 1.6e-6. With det = a c - b^2 in float32 (both
    // ~1e21 here) it is 59.8 dB, max 3.4e-3, depth 1.4e-2: hence Lagrange's identity.
    const Bounds bounds = MakeBounds(130.0, 2e-6, 1e-5);
    RenderBoth("flat 1e4 disc edge-on", MakeRawCloud(splats), MakeCamera(kW, kH, kF), bounds);
}

TEST_F(Stress, NearPlane) {
    // Splats at the near plane (0.2 as float32, 0.2 in double), one float ulp either side,
    // 1e-6 relative in front, and just behind; identity and tilted cameras.
    const double near = 0.2;
    const float near_f = static_cast<float>(near);
    const double depths[] = {near,
                             double(near_f),
                             double(std::nextafter(near_f, 1.0f)),
                             double(std::nextafter(near_f, 0.0f)),
                             near * (1 + 1e-6),
                             near * (1 - 1e-6),
                             0.19,
                             0.21};
    for (int tilted = 0; tilted < 2; ++tilted) {
        const Eigen::Matrix3d r = tilted ? TiltedRotation() : Eigen::Matrix3d::Identity();
        const Eigen::Vector3d center =
            tilted ? Eigen::Vector3d(0.3, -0.2, 0.7) : Eigen::Vector3d::Zero();
        std::vector<RawSplat> splats;
        int i = 0;
        for (double z : depths) {
            RawSplat p;
            const Eigen::Vector3d view((i % 4 - 1.5) * 0.05, (i / 4 - 0.5) * 0.05, z);
            p.position = r.transpose() * view + center;
            p.scale = Eigen::Vector3d(0.004, 0.003, 0.002);
            p.rot = AxisAngle(0.3 * i, Eigen::Vector3d(1, 1, 0));
            p.logit = Logit(0.9);
            p.f_dc = Eigen::Vector3d(0.1 * i, 0.5, 1.0 - 0.1 * i);
            splats.push_back(p);
            ++i;
        }
        // Measured 148.9 / 146.1 dB, max 9.5e-7 / 1.4e-6, depth 1.5e-7. A near cull in double
        // would keep the splats at 0.2f (> 0.2 in double) that the GPU culls (0.2f > 0.2f is
        // false): 5 vs 3 visible, 28.9 dB.
        const Bounds bounds = MakeBounds(130.0, 5e-6, 1e-6);
        const camera::PinholeCamera cam = MakeCamera(kW, kH, kF, r, center);
        RenderBoth(tilted ? "near plane, tilted camera" : "near plane", MakeRawCloud(splats), cam,
                   bounds);
        if (tilted) continue;  // the tilted positions round: which side they land on varies
        // The rule (3DGS: cull p_view.z <= 0.2f in float32): only the float32 depths above
        // 0.2f stay. RenderBoth checked that the GPU culls exactly the same splats.
        const auto projected = cpu::ProjectSplats(MakeRawCloud(splats), cam, {});
        const bool expected_visible[] = {false, false, true, false, true, false, false, true};
        for (size_t k = 0; k < projected.size(); ++k) {
            EXPECT_EQ(projected[k].IsVisible(), expected_visible[k]) << "depth " << depths[k];
        }
    }
}

TEST_F(Stress, CameraInsideASplat) {
    // The camera inside big splats whose centres lie in front of it (visible, a screen-filling
    // footprint), at it (culled: z = 0) and behind it (culled).
    std::vector<RawSplat> splats;
    const double zs[] = {0.25, 0.5, 0.0, -0.5};
    for (int i = 0; i < 4; ++i) {
        RawSplat p;
        p.position = Eigen::Vector3d(0.05 * i, -0.03 * i, zs[i]);
        p.scale = Eigen::Vector3d(2.0, 1.0, 3.0);
        p.rot = AxisAngle(0.6 * i + 0.2, Eigen::Vector3d(0, 1, 1));
        p.logit = Logit(0.4);
        p.f_dc = Eigen::Vector3d(0.8, 0.3 * i, 0.4);
        splats.push_back(p);
    }
    // Measured 151.5 dB, max 1.2e-7, depth 1.7e-7: float32 rounding only.
    const Bounds bounds = MakeBounds(135.0, 1e-6, 1e-6);
    RenderBoth("camera inside splats", MakeRawCloud(splats), MakeCamera(kW, kH, kF), bounds);
}

TEST_F(Stress, GuardBand) {
    // Splats far off-axis: x/z and y/z at 1, 1.01, 2, 10 and 100 times the guard band
    // 1.3 tan(fov / 2), large enough to reach into the image.
    const camera::PinholeCamera cam = MakeCamera(kW, kH, kF);
    const double lim_x = 1.3 * cam.GetTanHalfFovX(), lim_y = 1.3 * cam.GetTanHalfFovY();
    std::vector<RawSplat> splats;
    int i = 0;
    for (double factor : {1.0, 1.01, 2.0, 10.0, 100.0}) {
        for (int side = 0; side < 4; ++side, ++i) {
            RawSplat p;
            const double z = 2.0 + 0.1 * i;
            const double sx = side == 0 ? 1 : side == 1 ? -1 : 0.3;
            const double sy = side == 2 ? 1 : side == 3 ? -1 : -0.2;
            p.position = Eigen::Vector3d(sx * factor * lim_x * z, sy * factor * lim_y * z, z);
            const double reach = std::hypot(p.position.x(), p.position.y());
            p.scale = Eigen::Vector3d(0.4 * reach, 0.3 * reach, 0.5 * reach);
            p.rot = AxisAngle(0.3 * i, Eigen::Vector3d(1, -1, 2));
            p.logit = Logit(0.3);
            p.f_dc = Eigen::Vector3d(0.05 * i, 0.6, 0.3);
            splats.push_back(p);
        }
    }
    // Measured 145.4 dB, max 3.0e-7, depth 3.6e-7: float32 rounding only (the clamped
    // Jacobian is continuous, so a centre on the band edge is not a decision). 2 pixels sit
    // on the 1/255 threshold and are left out (ThresholdTies): the H100 skipped a splat of
    // alpha 1.00000014 / 255 there, 1.5e-3 off.
    const Bounds bounds = MakeBounds(130.0, 2e-6, 2e-6);
    RenderBoth("guard band", MakeRawCloud(splats), cam, bounds);
}

TEST_F(Stress, DepthsFromNearPlaneTo1e5) {
    // Depths 0.2 + 1e-4 .. 1e5 with scales growing with depth (a similar footprint), all
    // overlapping at the image centre, so the sort and the depth outputs span the range.
    std::vector<RawSplat> splats;
    const double zs[] = {0.2001, 0.3, 1.0, 10.0, 100.0, 1e3, 1e4, 1e5};
    int i = 0;
    for (double z : zs) {
        RawSplat p;
        // Centres off the pixel grid, so no tile bound lands exactly on a tile edge.
        p.position = Eigen::Vector3d(((i % 3 - 1) * 0.04 + 0.0013) * z,
                                     ((i % 2 - 0.5) * 0.05 + 0.0027) * z, z);
        p.scale = Eigen::Vector3d(0.06 * z, 0.05 * z, 0.04 * z);
        p.rot = AxisAngle(0.5 * i, Eigen::Vector3d(1, 0, 1));
        p.logit = Logit(0.45);
        p.f_dc = Eigen::Vector3d(0.1 * i, 1.0 - 0.1 * i, 0.5);
        splats.push_back(p);
        ++i;
    }
    // Measured 153.8 dB, max 3.0e-7, depth 1.4e-6 (float32 depth of 1e5 keeps 2^-24).
    const Bounds bounds = MakeBounds(135.0, 2e-6, 1e-5);
    RenderBoth("depths 0.2..1e5", MakeRawCloud(splats), MakeCamera(kW, kH, kF), bounds);
}

TEST_F(Stress, DepthsWhoseSquarePassesTheFloatRange) {
    // Depths 1e18 (z^2 = 1e36, a control) to 1e36 with scales growing with depth, centres off
    // the axis (x / z up to 0.3, where the Jacobian's z column, -f x / z^2, is a third of the
    // footprint). Past z ~ 1.8e19, z^2 overflows float32: the projection once divided by it
    // and dropped that column, giving the GPU conics 14x off the reference's (found by
    // fuzz_render_agreement: a splat at 1.9e26 with scale 1.9e26).
    std::vector<RawSplat> splats;
    const double zs[] = {1e18, 1e20, 1e24, 1e28, 1e32, 1e36};
    int i = 0;
    for (double z : zs) {
        RawSplat p;
        p.position = Eigen::Vector3d(((i % 3 - 1) * 0.3 + 0.0013) * z,
                                     ((i % 2 - 0.5) * 0.25 + 0.0027) * z, z);
        p.scale = Eigen::Vector3d(0.06 * z, 0.05 * z, 0.04 * z);
        p.rot = AxisAngle(0.5 * i, Eigen::Vector3d(1, 0, 1));
        p.logit = Logit(0.6);
        p.f_dc = Eigen::Vector3d(0.15 * i, 1.0 - 0.15 * i, 0.5);
        splats.push_back(p);
        ++i;
    }
    // Measured 146.9 dB, max 3.9e-7, depth 2.4e-6, conic 2.2e-7 relative: float32 rounding
    // only. With the quotient by z^2 it fails: 46.5 dB, max 0.036, conic 0.165 relative.
    const Bounds bounds = MakeBounds(130.0, 2e-6, 1e-5);
    RenderBoth("depths 1e18..1e36", MakeRawCloud(splats), MakeCamera(kW, kH, kF), bounds);
}

/// A small cluster of overlapping splats around `origin`, seen by a tilted camera 5 units
/// away (the scene of the far-from-origin case and its control at the origin).
void MakeOffsetScene(const Eigen::Vector3d& origin, std::vector<RawSplat>& splats,
                     camera::PinholeCamera& cam) {
    const Eigen::Matrix3d r = TiltedRotation();
    const Eigen::Vector3d center = origin - 5.0 * r.row(2).transpose();
    cam = MakeCamera(kW, kH, kF, r, center);
    for (int i = 0; i < 12; ++i) {
        RawSplat p;
        p.position = origin + Eigen::Vector3d(0.3 * std::sin(i), 0.25 * std::cos(1.3 * i),
                                              0.2 * std::sin(2.1 * i));
        p.scale = Eigen::Vector3d(0.15, 0.1, 0.05);
        p.rot = AxisAngle(0.5 * i, Eigen::Vector3d(1, 2, 0.5));
        p.logit = Logit(0.6);
        p.f_dc = Eigen::Vector3d(0.08 * i, 0.5, 1.0 - 0.08 * i);
        splats.push_back(p);
    }
}

TEST_F(Stress, SceneAndCamera1e5FromTheOrigin) {
    for (double offset : {0.0, 1e5}) {
        std::vector<RawSplat> splats;
        camera::PinholeCamera cam;
        MakeOffsetScene(Eigen::Vector3d(offset, -offset, offset), splats, cam);
        // Measured 143.1 dB (origin) and 143.8 dB (1e5), max 1.3e-6, depth 2.0e-7. Without the
        // camera-relative projection (R p + t in float32, 1e5-sized terms): 59.9 dB, max
        // 2.3e-2, depth 1.8e-2. The camera-relative depth order is the knob for such scenes:
        // the default reproduces the original rasterizer, whose float32 world-space depth and
        // centre are that coarse here (the CPU reference's decisions then follow its centre,
        // off by pixels: 77.9 dB against the GPU at 1e5; docs/accuracy.md).
        const Bounds bounds = MakeBounds(130.0, 5e-6, 1e-6);
        RenderConfig config;
        config.depth_order = DepthOrder::kCameraRelative;
        RenderBoth(offset == 0 ? "offset 0 (control)" : "offset 1e5", MakeRawCloud(splats), cam,
                   bounds, config);
    }
}

TEST_F(Stress, OpacityLogitsOfPlusMinus100) {
    // sigmoid(100) = 1 (alpha clamps at 0.99), sigmoid(-100) = 3.7e-44 (a float32 subnormal:
    // alpha < 1/255, skipped), interleaved with ordinary ones.
    std::vector<RawSplat> splats;
    const double logits[] = {100.0, -100.0, 0.0, 100.0, -100.0, 2.0, 88.0, -88.0, 1e4, -1e4};
    int i = 0;
    for (double logit : logits) {
        RawSplat p;
        p.position = Eigen::Vector3d((i % 5 - 2) * 0.25, (i / 5 - 0.5) * 0.3, 3.0 + 0.2 * i);
        p.scale = Eigen::Vector3d(0.3, 0.2, 0.25);
        p.rot = AxisAngle(0.4 * i, Eigen::Vector3d(2, 1, 1));
        p.logit = logit;
        p.f_dc = Eigen::Vector3d(0.1 * i, 0.7, 0.2);
        splats.push_back(p);
        ++i;
    }
    // Measured 151.5 dB, max 2.4e-7, depth 2.4e-7: float32 rounding only.
    const Bounds bounds = MakeBounds(135.0, 1e-6, 1e-6);
    RenderBoth("opacity logits +-100", MakeRawCloud(splats), MakeCamera(kW, kH, kF), bounds);
}

TEST_F(Stress, UnnormalisedAndNearZeroQuaternions) {
    // The same rotation stored at norms 1e3, 1, 1e-3, 1e-20, 1e-38 and 1e-44 (float32
    // subnormal), plus the zero quaternion: both renderers normalise (in double, at packing
    // on the GPU side); zero is the identity on both.
    std::vector<RawSplat> splats;
    const Eigen::Vector4d unit = AxisAngle(0.9, Eigen::Vector3d(1, 2, 3));
    const double norms[] = {1e3, 1.0, 1e-3, 1e-20, 1e-38, 1e-44, 0.0};
    int i = 0;
    for (double norm : norms) {
        RawSplat p;
        p.position = Eigen::Vector3d((i % 4 - 1.5) * 0.35, (i / 4 - 0.5) * 0.4, 3.0);
        p.scale = Eigen::Vector3d(0.25, 0.05, 0.1);
        p.rot = unit * norm;
        p.logit = Logit(0.8);
        p.f_dc = Eigen::Vector3d(0.9, 0.1 * i, 0.4);
        splats.push_back(p);
        ++i;
    }
    // Measured 149.6 dB, max 3.9e-7, depth 1.6e-7: float32 rounding only.
    const Bounds bounds = MakeBounds(135.0, 2e-6, 1e-6);
    RenderBoth("quaternions 1e3..1e-44, 0", MakeRawCloud(splats), MakeCamera(kW, kH, kF), bounds);
}

TEST_F(Stress, ShCoefficientsOf1e4) {
    // Degree 3, every rest coefficient +-1e4 (and f_dc 1e4): colours up to ~1e5 where the
    // bands add up and clamped to 0 where they cancel below -0.5; seen from a tilted camera
    // so every band is non-zero.
    std::vector<RawSplat> splats;
    for (int i = 0; i < 9; ++i) {
        RawSplat p;
        p.position = Eigen::Vector3d((i % 3 - 1) * 0.5, (i / 3 - 1) * 0.4, 3.0 + 0.1 * i);
        p.scale = Eigen::Vector3d(0.15, 0.12, 0.1);
        p.rot = AxisAngle(0.3 * i, Eigen::Vector3d(1, 0, 1));
        p.logit = Logit(0.5);
        p.f_dc = Eigen::Vector3d(i % 2 ? 1e4 : -1e4, 1e4, 0.0);
        for (int k = 0; k < 45; ++k) p.f_rest.push_back(((k * 7 + i * 3) % 5 < 2) ? -1e4 : 1e4);
        splats.push_back(p);
    }
    const Eigen::Matrix3d r = TiltedRotation();
    const camera::PinholeCamera cam =
        MakeCamera(kW, kH, kF, r, Eigen::Vector3d(0, 0, 3.4) - 3.0 * r.row(2).transpose());
    // Measured 143.6 dB relative to the brightest value (5.8e3), max 8.3e-3 (1.4e-6 of it):
    // the float32 SH sum rounds each partial sum of terms up to ~1.2e4 (2^-24 x 2e5 = 1.2e-2
    // per addition at most); depth 2.7e-7.
    Bounds bounds = MakeBounds(130.0, 4e-2, 1e-6);
    bounds.peak = 0;  // relative to the brightest value
    RenderBoth("SH degree 3, coefficients 1e4", MakeRawCloud(splats, 3), cam, bounds);
}

}  // namespace
}  // namespace tests
}  // namespace open3d
