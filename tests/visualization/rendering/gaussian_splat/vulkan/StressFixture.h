// The numerical stress suite's fixture (StressTest.cpp, StressResolutionTest.cpp): each case's
// scene rendered by the CPU reference and the "vulkan" backend and compared within its Bounds.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "GeometryStageComparison.h"
#include "StressTestScene.h"
#include "open3d/t/geometry/ImageMetrics.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"
#include "visualization/rendering/gaussian_splat/vulkan/VulkanTestFixture.h"

namespace open3d {
namespace tests {
namespace stress_suite {

using namespace visualization::rendering;
using vulkan::GaussianGeometryStageRunner;
using vulkan::GaussianSplatVulkanBackend;
using namespace stress;

/// Acceptance bounds of one case (colour PSNR and max abs error, expected depth relative
/// error where both renderers cover the pixel); each is justified where the case sets it.
struct Bounds {
    double min_psnr_db = 130.0;
    double max_abs = 1e-6;
    double max_depth_rel = 1e-6;
    double peak = 1.0;  // PSNR signal peak; 0: the reference's brightest value
};

inline Bounds MakeBounds(double min_psnr_db, double max_abs, double max_depth_rel) {
    return {min_psnr_db, max_abs, max_depth_rel};
}

class Stress : public VulkanTest {
protected:
    /// Renders `cloud` with both backends, checks finiteness and geometry stage (culled set, tile
    /// lists, order) against the reference, the same coverage and median depth at every
    /// pixel, prints one line of the docs table and checks `bounds`.
    void RenderBoth(const std::string& name, const t::geometry::PointCloud& cloud,
                    const camera::PinholeCamera& cam, const Bounds& bounds,
                    const RenderConfig& config = {}) {
        SCOPED_TRACE(name);
        auto backend = MakeBackend();
        backend->SetScene(cloud);
        const RenderOutput gpu = backend->Render(cam, config);
        const RenderOutput ref = cpu::RenderReference(cloud, cam, config);

        for (const auto& [label, image] :
             {std::pair{"gpu colour", &gpu.color}, std::pair{"gpu depth", &gpu.depth_expected},
              std::pair{"gpu median", &gpu.depth_median}, std::pair{"cpu colour", &ref.color},
              std::pair{"cpu depth", &ref.depth_expected},
              std::pair{"cpu median", &ref.depth_median}}) {
            EXPECT_EQ(CountNonFinite(*image), 0) << label << " has NaN or Inf";
        }
        EXPECT_EQ(gpu.stats.error_flags, ref.stats.error_flags);

        // Geometry stage splat by splat and tile by tile (GeometryStageComparison.h): a cull or
        // tile rectangle may differ only where float32 lands on the other side of a border.
        GaussianGeometryStageRunner runner(Context(), PackGaussianSplatAttrs(cloud), 1u << 20);
        const GeometryStageComparison a =
            CompareGeometryStage(cloud, cam, config, runner.Run(cam, config));
        EXPECT_EQ(a.cull_flips_unexplained, 0) << a.Summary();
        EXPECT_EQ(a.errors.radius_off_more, 0) << a.Summary();
        EXPECT_EQ(a.tiles_misordered, 0) << a.Summary();
        EXPECT_EQ(a.gpu_span_mismatches, 0) << a.Summary();
        EXPECT_EQ(a.visible_list_misordered, 0) << a.Summary();
        // The cases keep their splats clear of tile borders, so no flip is allowed at all.
        EXPECT_EQ(a.border_splats.size(), 0u) << a.Summary();
        EXPECT_EQ(gpu.stats.num_visible, ref.stats.num_visible);
        EXPECT_EQ(gpu.stats.num_tile_entries, ref.stats.num_tile_entries);

        // Pixels on a composite threshold are left out (ThresholdTies): the GPU's value is
        // replaced by the reference's there.
        const std::vector<uint8_t> tied = ThresholdTies(cloud, cam);
        int64_t num_tied = 0;
        t::geometry::Image gpu_color(gpu.color.AsTensor());  // a copy
        float* gc = gpu_color.Data<float>();
        const float* rc = ref.color.Data<float>();
        double ref_max = 0.0;
        for (int64_t i = 0; i < ref.color.NumPixels(); ++i) {
            num_tied += tied[i];
            for (int c = 0; c < 4; ++c) {
                if (tied[i]) gc[i * 4 + c] = rc[i * 4 + c];
                ref_max = std::max(ref_max, double(rc[i * 4 + c]));
            }
        }
        EXPECT_LE(num_tied, ref.color.NumPixels() / 1000) << "too many pixels on a threshold";
        const double peak = bounds.peak > 0 ? bounds.peak : ref_max;
        const auto m = t::geometry::ComputeImageErrorMetrics(gpu_color, ref.color, peak, 0.0);
        double depth_rel = 0.0;
        int64_t coverage_mismatch = 0, median_mismatch = 0;
        const float* gd = gpu.depth_expected.Data<float>();
        const float* rd = ref.depth_expected.Data<float>();
        const float* gm = gpu.depth_median.Data<float>();
        const float* rm = ref.depth_median.Data<float>();
        for (int64_t i = 0; i < gpu.depth_expected.NumPixels(); ++i) {
            if (tied[i]) continue;
            if ((gd[i] > 0) != (rd[i] > 0)) {
                ++coverage_mismatch;
            } else if (rd[i] > 0) {
                depth_rel = std::max(depth_rel, std::abs(double(gd[i]) - rd[i]) / rd[i]);
            }
            // The median is one splat's depth: equal to rounding unless 1 - T >= 0.5 flips.
            if (std::abs(double(gm[i]) - rm[i]) > 1e-5 * std::abs(double(rm[i]))) {
                ++median_mismatch;
            }
        }
        std::printf(
            "[stress] %-30s %4dx%-4d visible %2lld entries %5lld tied px %3lld | PSNR %6.1f dB, "
            "max %.3g (of %.3g), depth rel %.3g\n",
            name.c_str(), cam.width, cam.height, static_cast<long long>(ref.stats.num_visible),
            static_cast<long long>(ref.stats.num_tile_entries), static_cast<long long>(num_tied),
            m.psnr_db, m.max_abs_error, ref_max, depth_rel);
        std::printf("[stress]   geometry stage: %s\n", a.Summary().c_str());
        EXPECT_GE(m.psnr_db, bounds.min_psnr_db);
        EXPECT_LE(m.max_abs_error, bounds.max_abs);
        EXPECT_LE(depth_rel, bounds.max_depth_rel);
        EXPECT_EQ(coverage_mismatch, 0) << "pixels covered by one renderer only";
        EXPECT_EQ(median_mismatch, 0) << "pixels with another median depth";
    }
};

// 64x48, 60 px focal length (tan(fov_x / 2) = 0.53): the default view of the small cases.
constexpr int kW = 64, kH = 48;
constexpr double kF = 60.0;

}  // namespace stress_suite
}  // namespace tests
}  // namespace open3d
