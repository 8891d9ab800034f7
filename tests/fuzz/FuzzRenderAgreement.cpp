// Differential libFuzzer harness of the two renderers: the input becomes up to six splats
// and a camera, with magnitudes from 1e-30 to 1e30 (positions, scales, rotations, opacity
// logits, focal length, image size 1..48 px), and the Vulkan geometry stage (lavapipe here)
// is compared with the CPU reference splat by splat and tile by tile
// (GeometryStageComparison): every difference must be one that float32 against double
// explains at a decision border. Anything else aborts, which libFuzzer reports with the input.
// docs/accuracy.md "Extremes" has the rules both renderers share.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanContext.h"
#include "visualization/rendering/gaussian_splat/vulkan/GeometryStageComparison.h"
#include "visualization/rendering/gaussian_splat/vulkan/StressTestScene.h"

namespace {

using namespace open3d;
namespace rendering = visualization::rendering;

// Reads the input a byte at a time; past its end every read is 0.
class Bytes {
public:
    Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}
    uint8_t Next() { return at_ < size_ ? data_[at_++] : 0; }
    // A value of magnitude 10^e, e in [-30, 30] picked by one byte (most in [-3, 3]),
    // mantissa and sign from another.
    double Magnitude() {
        const uint8_t e = Next(), m = Next();
        const int exponent = e < 192 ? int(e % 7) - 3 : int(e % 61) - 30;
        const double value = (1.0 + (m & 0x7f) / 128.0) * std::pow(10.0, exponent);
        return m & 0x80 ? -value : value;
    }
    double Unit() { return Next() / 255.0; }

private:
    const uint8_t* data_;
    size_t size_;
    size_t at_ = 0;
};

rendering::vulkan::VulkanContext& Context() {
    static std::unique_ptr<rendering::vulkan::VulkanContext> context =
        rendering::vulkan::VulkanContext::CreateHeadless();
    return *context;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    Bytes in(data, size);
    const int n = 1 + in.Next() % 6;
    std::vector<tests::stress::RawSplat> splats(n);
    for (tests::stress::RawSplat& s : splats) {
        // Mostly in front of the camera (z > 0), at any distance.
        s.position = Eigen::Vector3d(in.Magnitude(), in.Magnitude(), std::abs(in.Magnitude()));
        s.scale = Eigen::Vector3d(std::abs(in.Magnitude()), std::abs(in.Magnitude()),
                                  std::abs(in.Magnitude()));
        s.rot = Eigen::Vector4d(in.Magnitude(), in.Magnitude(), in.Magnitude(), in.Magnitude());
        s.logit = in.Magnitude();
        s.f_dc = Eigen::Vector3d(in.Unit() - 0.5, in.Unit() - 0.5, in.Unit() - 0.5);
    }
    const int width = 1 + in.Next() % 48, height = 1 + in.Next() % 48;
    const double focal = std::pow(10.0, in.Unit() * 5.0);  // 1 .. 1e5 px
    rendering::RenderConfig config;
    config.antialias = in.Next() & 1;
    const t::geometry::PointCloud cloud = tests::stress::MakeRawCloud(splats);
    const camera::PinholeCamera camera = tests::stress::MakeCamera(width, height, focal);
    try {
        cloud.ValidateGaussianSplat();  // what a reader would refuse never reaches a renderer
    } catch (const core::Open3DError&) {
        return 0;
    }
    rendering::vulkan::GaussianGeometryStageRunner runner(
        Context(), rendering::PackGaussianSplatAttrs(cloud), 1u << 16);
    const tests::GeometryStageComparison c =
        tests::CompareGeometryStage(cloud, camera, config, runner.Run(camera, config));
    const bool agree = c.cull_flips_unexplained == 0 && c.errors.radius_off_more == 0 &&
                       c.tiles_misordered == 0 && c.gpu_span_mismatches == 0 &&
                       c.visible_list_misordered == 0;
    if (!agree) {
        std::fprintf(stderr, "renderers disagree: %s\n", c.Summary().c_str());
        std::abort();
    }
    return 0;
}
