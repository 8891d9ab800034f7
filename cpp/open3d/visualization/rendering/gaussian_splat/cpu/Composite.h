// Composite stage of the CPU reference: per-tile front-to-back blending with the 3DGS rules
// (docs/DESIGN.md "Numerical rules"): the blended values in double precision, the threshold
// decisions (alpha >= 1/255, the transmittance stop) in float32 as the original rasterizer
// takes them.
#pragma once

#include <vector>

#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

/// The compositing thresholds as the CUDA rasterizer's float constants, widened to double.
inline constexpr double kMaxAlpha = static_cast<double>(0.99f);
inline constexpr double kMinAlpha = static_cast<double>(1.0f / 255.0f);
inline constexpr double kMinTransmittance = static_cast<double>(0.0001f);

/// Composites `lists` into output.color / depth_expected / depth_median (allocated at
/// width x height), multi-threaded over tiles. See RenderOutput for the image contents.
void CompositeTiles(const std::vector<ProjectedSplat>& splats, const TileLists& lists, int width,
                    int height, const RenderConfig& config, const CompositeInputs& inputs,
                    RenderOutput& output);

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
