#include "open3d/visualization/rendering/gaussian_splat/cpu/Composite.h"

#include <algorithm>

#include <fmt/format.h>
#include <cmath>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/core/ParallelFor.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/PixelBlend.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

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
        // The colour (RGBA32F), the two depths (float32) and the ID (int32) of every pixel.
        const uint64_t per_pixel = 4 * 4 + 4 + 4 + (inputs.splat_id ? 4 : 0);
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
    float* color = output.color.Data<float>();                    // [H, W, 4]
    float* depth_expected = output.depth_expected.Data<float>();  // [H, W, 1]
    float* depth_median = output.depth_median.Data<float>();      // [H, W, 1]
    int32_t* splat_id = nullptr;                                  // [H, W, 1]
    output.splat_id = t::geometry::Image();
    if (inputs.splat_id) {
        output.splat_id = t::geometry::Image(height, width, 1, core::Dtype::Int32);
        splat_id = output.splat_id.Data<int32_t>();
    }
    const float* scene = scene_depth ? scene_depth->Data<float>() : nullptr;  // [H, W, 1]
    const Eigen::Vector3d bg = config.background;

    core::ParallelFor(
        grid.NumTiles(),
        [&](int64_t tile) {
            const int tx = static_cast<int>(tile % grid.tiles_x);
            const int ty = static_cast<int>(tile / grid.tiles_x);
            const std::vector<TileSplat> local = TileSplats(splats, lists, tile);
            const int x_end = std::min(width, (tx + 1) * kTileSize);
            const int y_end = std::min(height, (ty + 1) * kTileSize);
            for (int py = ty * kTileSize; py < y_end; ++py) {
                for (int px = tx * kTileSize; px < x_end; ++px) {
                    const int64_t pixel = static_cast<int64_t>(py) * width + px;
                    // Scene depth <= 0 means no geometry there (Filament clears to 0).
                    const double limit_depth =
                        scene && scene[pixel] > 0.0f ? scene[pixel] : HUGE_VAL;
                    double c[3] = {0.0, 0.0, 0.0};
                    double weighted_depth = 0.0;
                    double median = 0.0;
                    bool median_found = false;
                    double best_weight = 0.0;  // the dominant splat: strictly larger wins
                    int32_t best = -1;
                    const double transmittance =
                        BlendPixel(local, px, py, limit_depth,
                                   [&](const TileSplat& s, double w, double transmittance_after) {
                                       c[0] += s.r * w;
                                       c[1] += s.g * w;
                                       c[2] += s.b * w;
                                       weighted_depth += s.depth * w;
                                       if (!median_found && 1.0 - transmittance_after >= 0.5) {
                                           median = s.depth;
                                           median_found = true;
                                       }
                                       if (w > best_weight) {
                                           best_weight = w;
                                           best = static_cast<int32_t>(s.index);
                                       }
                                   });
                    const double accumulated = 1.0 - transmittance;
                    for (int ch = 0; ch < 3; ++ch) {
                        color[pixel * 4 + ch] = static_cast<float>(c[ch] + transmittance * bg[ch]);
                    }
                    color[pixel * 4 + 3] = static_cast<float>(accumulated);
                    depth_expected[pixel] =
                        accumulated > 0.0 ? static_cast<float>(weighted_depth / accumulated) : 0.f;
                    depth_median[pixel] = static_cast<float>(median);
                    if (splat_id) splat_id[pixel] = best;
                }
            }
        },
        1);
}

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
