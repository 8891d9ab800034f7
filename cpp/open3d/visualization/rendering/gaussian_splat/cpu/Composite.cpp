#include "open3d/visualization/rendering/gaussian_splat/cpu/Composite.h"

#include <algorithm>

#include <fmt/format.h>
#include <cmath>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/core/ParallelFor.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

namespace {

// What the blending loop reads per splat, packed so a tile's list is contiguous.
struct TileSplat {
    double x, y;
    double conic_a, conic_b, conic_c;
    double opacity;
    double r, g, b;
    double depth;
    // The same splat in float32 as the original rasterizer holds it, for its decisions.
    float original_x, original_y;
    float conic_a_f, conic_b_f, conic_c_f;
    float opacity_f;
};

// The original's alpha of a splat at pixel (px, py), float32 in its operation order
// (forward.cu renderCUDA) with the multiply-adds nvcc fuses there fused (LLVM's contraction
// takes the left product of a sum first): power = fma(-0.5, fma(a dx, dx, (c dy) dy),
// -((b dx) dy)), alpha = min(0.99, o exp(power)); 0 where it skips the splat (power > 0).
// Deciding the 1/255 and transmittance thresholds on these values instead of the double
// ones keeps a splat within rounding of a threshold where the original puts it: the double
// alpha differed from its float32 one by 1e-7, enough to flip a 1/255 decision.
float OriginalAlpha(const TileSplat& s, int px, int py) {
    const float dx = s.original_x - static_cast<float>(px);
    const float dy = s.original_y - static_cast<float>(py);
    const float sum = std::fma(s.conic_a_f * dx, dx, (s.conic_c_f * dy) * dy);
    const float power = std::fma(-0.5f, sum, -((s.conic_b_f * dx) * dy));
    if (power > 0.0f) return 0.0f;
    return std::min(0.99f, s.opacity_f * std::exp(power));
}

}  // namespace

void CompositeTiles(const std::vector<ProjectedSplat>& splats, const TileLists& lists, int width,
                    int height, const RenderConfig& config, const CompositeInputs& inputs,
                    RenderOutput& output) {
    const TileGrid& grid = lists.grid;
    if (grid.tiles_x != TileGrid::ForImage(width, height).tiles_x ||
        grid.tiles_y != TileGrid::ForImage(width, height).tiles_y) {
        core::ThrowError("CompositeTiles: tile grid {}x{} does not match a {}x{} image",
                         grid.tiles_x, grid.tiles_y, width, height);
    }
    const t::geometry::Image* scene_depth = inputs.scene_depth;
    if (scene_depth &&
        (scene_depth->GetRows() != height || scene_depth->GetCols() != width ||
         scene_depth->GetChannels() != 1 || scene_depth->GetDtype() != core::Dtype::Float32)) {
        core::ThrowError("CompositeTiles: scene depth must be Float32 [{}, {}, 1]", height, width);
    }
    {
        // The colour (RGBA32F) and the two depths (float32) of every pixel.
        const uint64_t per_pixel = 4 * 4 + 4 + 4;
        const uint64_t need = per_pixel * uint64_t(width) * height;
        const uint64_t available = core::AvailableHostMemory();
        const double scale = need > available ? std::sqrt(double(available) / need) * 0.9 : 1.0;
        core::RequireHostMemory(need, fmt::format("cpu backend: a {}x{} image", width, height),
                                fmt::format("{}x{} would fit", std::max(1, int(width * scale)),
                                            std::max(1, int(height * scale))));
    }
    output.color = t::geometry::Image(height, width, 4, core::Dtype::Float32);
    output.depth_expected = t::geometry::Image(height, width, 1, core::Dtype::Float32);
    output.depth_median = t::geometry::Image(height, width, 1, core::Dtype::Float32);
    float* color = output.color.Data<float>();                                // [H, W, 4]
    float* depth_expected = output.depth_expected.Data<float>();              // [H, W, 1]
    float* depth_median = output.depth_median.Data<float>();                  // [H, W, 1]
    const float* scene = scene_depth ? scene_depth->Data<float>() : nullptr;  // [H, W, 1]
    const Eigen::Vector3d bg = config.background;

    core::ParallelFor(
        grid.NumTiles(),
        [&](int64_t tile) {
            const int tx = static_cast<int>(tile % grid.tiles_x);
            const int ty = static_cast<int>(tile / grid.tiles_x);
            std::vector<TileSplat> local;
            local.reserve(lists.offsets[tile + 1] - lists.offsets[tile]);
            for (uint64_t k = lists.offsets[tile]; k < lists.offsets[tile + 1]; ++k) {
                const ProjectedSplat& s = splats[lists.splat_indices[k]];
                local.push_back({s.x, s.y, s.conic_a, s.conic_b, s.conic_c, s.opacity, s.color[0],
                                 s.color[1], s.color[2], s.depth, s.original_x, s.original_y,
                                 float(s.conic_a), float(s.conic_b), float(s.conic_c),
                                 float(s.opacity)});
            }
            const int x_end = std::min(width, (tx + 1) * kTileSize);
            const int y_end = std::min(height, (ty + 1) * kTileSize);
            for (int py = ty * kTileSize; py < y_end; ++py) {
                for (int px = tx * kTileSize; px < x_end; ++px) {
                    const int64_t pixel = static_cast<int64_t>(py) * width + px;
                    // Scene depth <= 0 means no geometry there (Filament clears to 0).
                    const double limit_depth =
                        scene && scene[pixel] > 0.0f ? scene[pixel] : HUGE_VAL;
                    double transmittance = 1.0;
                    float transmittance_f = 1.0f;  // the original's T, for its stop decision
                    double c[3] = {0.0, 0.0, 0.0};
                    double weighted_depth = 0.0;
                    double median = 0.0;
                    bool median_found = false;
                    for (const TileSplat& s : local) {
                        if (s.depth > limit_depth) continue;
                        // Whether the splat counts, and whether it ends the pixel, is the
                        // original's float32 decision (OriginalAlpha); what it adds is double.
                        const float alpha_f = OriginalAlpha(s, px, py);
                        if (!(alpha_f >= static_cast<float>(kMinAlpha))) continue;
                        const float next_t_f = transmittance_f * (1.0f - alpha_f);
                        // Stop before blending: this splat would make the pixel opaque.
                        if (next_t_f < static_cast<float>(kMinTransmittance)) break;
                        transmittance_f = next_t_f;
                        // Pixel (px, py) is evaluated at (px, py), as in 3DGS.
                        const double dx = s.x - px;
                        const double dy = s.y - py;
                        const double power =
                            std::min(0.0, -0.5 * (s.conic_a * dx * dx + s.conic_c * dy * dy) -
                                              s.conic_b * dx * dy);
                        const double alpha = std::min(kMaxAlpha, s.opacity * std::exp(power));
                        const double next_t = transmittance * (1.0 - alpha);
                        const double w = alpha * transmittance;
                        c[0] += s.r * w;
                        c[1] += s.g * w;
                        c[2] += s.b * w;
                        weighted_depth += s.depth * w;
                        transmittance = next_t;
                        if (!median_found && 1.0 - transmittance >= 0.5) {
                            median = s.depth;
                            median_found = true;
                        }
                    }
                    const double accumulated = 1.0 - transmittance;
                    for (int ch = 0; ch < 3; ++ch) {
                        color[pixel * 4 + ch] = static_cast<float>(c[ch] + transmittance * bg[ch]);
                    }
                    color[pixel * 4 + 3] = static_cast<float>(accumulated);
                    depth_expected[pixel] =
                        accumulated > 0.0 ? static_cast<float>(weighted_depth / accumulated) : 0.f;
                    depth_median[pixel] = static_cast<float>(median);
                }
            }
        },
        1);
}

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
