// Helpers of the composite stage tests: composite stage is tested in isolation from geometry stage.
// The CPU reference's projection and tile lists are turned into exactly what geometry stage hands
// over (GaussianProjectedSplat records rounded to float32, (tile, splat) entries sorted by tile in
// depth order), composited on the GPU and compared with cpu::CompositeTiles.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "open3d/visualization/rendering/gaussian_splat/cpu/Composite.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"
#include "visualization/rendering/gaussian_splat/vulkan/support/GaussianCompositeStageRunner.h"

namespace open3d {
namespace tests {

namespace rendering = visualization::rendering;
namespace gpu = visualization::rendering::vulkan;

/// The geometry stage hand-over for the reference's splats and lists.
inline gpu::CompositeStageRunInputs ToCompositeStageInputs(
    const std::vector<rendering::cpu::ProjectedSplat>& splats,
    const rendering::cpu::TileLists& lists, int width, int height) {
    gpu::CompositeStageRunInputs in;
    in.width = static_cast<uint32_t>(width);
    in.height = static_cast<uint32_t>(height);
    in.projected.resize(splats.size());
    for (size_t i = 0; i < splats.size(); ++i) {
        const rendering::cpu::ProjectedSplat& s = splats[i];
        if (!s.IsVisible()) continue;
        rendering::shader::GaussianProjectedSplat& p = in.projected[i];
        p.center_x = float(s.x);
        p.center_y = float(s.y);
        p.depth = float(s.depth);
        p.opacity = float(s.opacity);
        p.conic = {float(s.conic_a), float(s.conic_b), float(s.conic_c)};
        // The culling threshold and det_q, as the projection stores them (the composite
        // skips pixels past the threshold).
        p.cull_threshold = rendering::shader::TileCullThreshold(float(s.opacity), float(s.conic_a),
                                                                float(s.conic_c), float(s.det_q));
        p.color = {float(s.color[0]), float(s.color[1]), float(s.color[2])};
        p.det_q = float(s.det_q);
        p.rect_min = uint32_t(s.rect_min_x) | uint32_t(s.rect_min_y) << 16;
        p.rect_max = uint32_t(s.rect_max_x) | uint32_t(s.rect_max_y) << 16;
        p.num_entries = uint32_t(s.NumTiles());
        p.radius = uint32_t(s.radius);
    }
    for (int64_t tile = 0; tile + 1 < static_cast<int64_t>(lists.offsets.size()); ++tile) {
        for (uint64_t k = lists.offsets[tile]; k < lists.offsets[tile + 1]; ++k) {
            in.entry_tiles.push_back(static_cast<uint32_t>(tile));
            in.entry_splats.push_back(lists.splat_indices[k]);
        }
    }
    return in;
}

/// A visible splat for analytic cases: an axis-aligned Gaussian of standard deviation
/// `sigma` pixels (conic 1 / sigma^2), 3-sigma radius and tile rectangle like the reference.
inline rendering::cpu::ProjectedSplat MakeSplat(double x, double y, double depth, double sigma,
                                                double opacity, std::array<double, 3> color,
                                                int width, int height) {
    rendering::cpu::ProjectedSplat s;
    s.cull = rendering::cpu::CullReason::kVisible;
    s.x = x;
    s.y = y;
    s.original_x = static_cast<float>(x);  // the centre the composite's decisions read
    s.original_y = static_cast<float>(y);
    s.depth = depth;
    s.cov_a = s.cov_c = sigma * sigma;
    s.conic_a = s.conic_c = 1.0 / (sigma * sigma);
    s.det_q = s.conic_a * s.conic_c;  // b = 0
    s.radius = static_cast<int>(std::ceil(3.0 * sigma));
    s.opacity = opacity;
    s.color = color;
    rendering::cpu::ComputeTileRect(x, y, s.radius,
                                    rendering::cpu::TileGrid::ForImage(width, height), s);
    return s;
}

/// Reference composite; `scene_z` is [H, W] view z (+inf = nothing) or empty.
inline rendering::RenderOutput ReferenceComposite(
    const std::vector<rendering::cpu::ProjectedSplat>& splats,
    const rendering::cpu::TileLists& lists, int width, int height,
    const rendering::RenderConfig& config, const std::vector<float>& scene_z = {}) {
    rendering::RenderOutput out;
    rendering::CompositeInputs inputs;
    t::geometry::Image scene;
    if (!scene_z.empty()) {
        scene = t::geometry::Image(height, width, 1, core::Dtype::Float32);
        std::copy(scene_z.begin(), scene_z.end(), scene.Data<float>());
        inputs.scene_depth = &scene;
    }
    rendering::cpu::CompositeTiles(splats, lists, width, height, config, inputs, out);
    return out;
}

/// Error of a GPU image against the reference's, over every channel.
struct ErrorStats {
    double psnr_db = std::numeric_limits<double>::infinity();  ///< peak 1
    double max_abs = 0.0;
    double p999_abs = 0.0;           ///< 99.9th percentile of the absolute error
    double fraction_over_lsb = 0.0;  ///< share of values off by more than 1/255
    size_t worst_index = 0;          ///< index of the largest error
    float worst_gpu = 0.f, worst_reference = 0.f;
};

inline ErrorStats CompareValues(const float* gpu_values, const float* reference, size_t n) {
    ErrorStats stats;
    if (n == 0) return stats;
    std::vector<double> errors(n);
    double squared = 0.0;
    size_t over = 0;
    for (size_t i = 0; i < n; ++i) {
        errors[i] = std::abs(double(gpu_values[i]) - double(reference[i]));
        squared += errors[i] * errors[i];
        if (errors[i] > 1.0 / 255.0) ++over;
        if (errors[i] > stats.max_abs || std::isnan(errors[i])) {
            stats.max_abs =
                std::isnan(errors[i]) ? std::numeric_limits<double>::infinity() : errors[i];
            stats.worst_index = i;
            stats.worst_gpu = gpu_values[i];
            stats.worst_reference = reference[i];
        }
    }
    const double mse = squared / double(n);
    stats.psnr_db =
        mse > 0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
    stats.fraction_over_lsb = double(over) / double(n);
    const size_t k = std::min(n - 1, static_cast<size_t>(std::floor(0.999 * double(n - 1))));
    std::nth_element(errors.begin(), errors.begin() + k, errors.end());
    stats.p999_abs = errors[k];
    return stats;
}

inline ErrorStats CompareImage(const std::vector<float>& gpu_values,
                               const t::geometry::Image& image) {
    const size_t n = static_cast<size_t>(image.GetRows() * image.GetCols() * image.GetChannels());
    EXPECT_EQ(gpu_values.size(), n);
    return CompareValues(gpu_values.data(), image.Data<float>(), std::min(n, gpu_values.size()));
}

}  // namespace tests
}  // namespace open3d
