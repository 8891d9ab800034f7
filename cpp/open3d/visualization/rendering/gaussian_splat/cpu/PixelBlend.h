// One pixel's front-to-back blend with the 3DGS rules (docs/DESIGN.md "Numerical rules"), shared
// by the composite (cpu/Composite.cpp) and what asks which splats a pixel shows
// (cpu/ViewSelection.cpp): the threshold decisions (alpha >= 1/255, the transmittance stop) in
// float32 as the original rasterizer takes them, the blended values in double.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "open3d/visualization/rendering/gaussian_splat/cpu/Composite.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

/// What the blending loop reads per splat, packed so a tile's list is contiguous.
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
    uint32_t index;  ///< the splat's index in the cloud
};

inline TileSplat MakeTileSplat(const ProjectedSplat& s, uint32_t index) {
    return {s.x,
            s.y,
            s.conic_a,
            s.conic_b,
            s.conic_c,
            s.opacity,
            s.color[0],
            s.color[1],
            s.color[2],
            s.depth,
            s.original_x,
            s.original_y,
            float(s.conic_a),
            float(s.conic_b),
            float(s.conic_c),
            float(s.opacity),
            index};
}

/// Tile `tile`'s splats of `lists`, front to back, as BlendPixel reads them.
inline std::vector<TileSplat> TileSplats(const std::vector<ProjectedSplat>& splats,
                                         const TileLists& lists, int64_t tile) {
    std::vector<TileSplat> local;
    local.reserve(lists.offsets[tile + 1] - lists.offsets[tile]);
    for (uint64_t k = lists.offsets[tile]; k < lists.offsets[tile + 1]; ++k) {
        local.push_back(MakeTileSplat(splats[lists.splat_indices[k]], lists.splat_indices[k]));
    }
    return local;
}

/// The original's alpha of a splat at pixel (px, py), float32 in its operation order
/// (forward.cu renderCUDA) with the multiply-adds nvcc fuses there fused (LLVM's contraction
/// takes the left product of a sum first): power = fma(-0.5, fma(a dx, dx, (c dy) dy),
/// -((b dx) dy)), alpha = min(0.99, o exp(power)); 0 where it skips the splat (power > 0).
/// Deciding the 1/255 and transmittance thresholds on these values instead of the double
/// ones keeps a splat within rounding of a threshold where the original puts it: the double
/// alpha differed from its float32 one by 1e-7, enough to flip a 1/255 decision.
inline float OriginalAlpha(const TileSplat& s, int px, int py) {
    const float dx = s.original_x - static_cast<float>(px);
    const float dy = s.original_y - static_cast<float>(py);
    const float sum = std::fma(s.conic_a_f * dx, dx, (s.conic_c_f * dy) * dy);
    const float power = std::fma(-0.5f, sum, -((s.conic_b_f * dx) * dy));
    if (power > 0.0f) return 0.0f;
    return std::min(0.99f, s.opacity_f * std::exp(power));
}

/// Blends `local` (one tile's splats, front to back) at pixel (px, py), skipping splats deeper
/// than `limit_depth`: on_blend(splat, weight alpha T, transmittance after it) for every splat
/// blended, in order. Returns the transmittance left.
template <class OnBlend>
double BlendPixel(const std::vector<TileSplat>& local, int px, int py, double limit_depth,
                  OnBlend&& on_blend) {
    double transmittance = 1.0;
    float transmittance_f = 1.0f;  // the original's T, for its stop decision
    for (const TileSplat& s : local) {
        if (s.depth > limit_depth) continue;
        // Whether the splat counts, and whether it ends the pixel, is the original's float32
        // decision (OriginalAlpha); what it adds is double.
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
            std::min(0.0, -0.5 * (s.conic_a * dx * dx + s.conic_c * dy * dy) - s.conic_b * dx * dy);
        const double alpha = std::min(kMaxAlpha, s.opacity * std::exp(power));
        const double next_t = transmittance * (1.0 - alpha);
        on_blend(s, alpha * transmittance, next_t);
        transmittance = next_t;
    }
    return transmittance;
}

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
