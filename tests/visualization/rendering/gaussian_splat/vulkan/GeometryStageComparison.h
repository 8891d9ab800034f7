// Compares a Vulkan geometry stage readback with the CPU reference (cpu/Projection,
// cpu/TileLists) splat by splat and tile by tile, and says where float32 (GPU)
// and double (reference) legitimately part: a cull or tile-rectangle decision
// that flips at a border, and the order of two splats whose depths are within
// float32 rounding of each other. Everything else must match exactly; the
// counts of the legitimate differences are reported and bounded by the tests.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"
#include "visualization/rendering/gaussian_splat/vulkan/support/GaussianGeometryStageRunner.h"

namespace open3d {
namespace tests {

/// Largest differences of the per-splat outputs over splats visible on both
/// sides.
struct ProjectionErrors {
    double center_px = 0.0;  ///< |x - x_ref|, |y - y_ref| (pixels)
    double depth_rel = 0.0;  ///< |z - z_ref| / z_ref
    double conic_rel = 0.0;  ///< max |conic - ref| / max(|conic_a_ref|, |conic_c_ref|)
    double opacity_abs = 0.0;
    double color_abs = 0.0;
    int64_t radius_off_by_one = 0;  ///< ceil() landed on the other integer
    int64_t radius_off_more = 0;    ///< must stay 0
    int64_t rect_differs = 0;       ///< tile rect differs (explained by radius or border)
    /// Same rect, but a row's culled span (shader::TileRowSpan) differs: the float32 inputs
    /// (centre, conic, opacity) differ by rounding on the two sides.
    int64_t span_differs = 0;
};

struct GeometryStageComparison {
    int64_t num_splats = 0;
    int64_t visible_cpu = 0;
    int64_t visible_gpu = 0;
    /// Splats culled on one side only; each is checked to sit at a decision
    /// border.
    int64_t cull_flips = 0;
    int64_t cull_flips_unexplained = 0;  ///< must stay 0
    ProjectionErrors errors;
    /// Splats whose tile set differs (a cull flip or a rect flip): excluded from
    /// the order check, their entries counted below.
    std::vector<uint32_t> border_splats;
    int64_t entries_cpu = 0;
    int64_t entries_gpu = 0;
    int64_t border_entries = 0;  ///< entries of border splats (on either side)
    /// Tiles whose GPU list (border splats removed) is not the reference set
    /// sorted by (GPU float32 depth, splat index): a sort bug; must stay 0.
    int64_t tiles_misordered = 0;
    /// Adjacent pairs ordered differently from the reference because their
    /// float32 depths round differently on the two sides; counted and bounded.
    int64_t depth_rounding_swaps = 0;
    /// Largest relative depth gap of such a pair (must be a rounding-sized gap).
    double depth_rounding_swap_max_rel = 0.0;
    int64_t visible_list_misordered = 0;  ///< GPU visible list not sorted by its own keys
    /// Splats whose GPU entries (when it emitted any) are not the TileRowSpan tiles of its
    /// own stored record, computed here in C++, plus filler entries: a shader bug; must stay 0.
    int64_t gpu_span_mismatches = 0;

    std::string Summary() const;
};

/// Runs the CPU reference and compares. `hidden` marks splats hidden by the
/// visibility mask (they must be absent from the GPU output; the reference
/// ignores them).
GeometryStageComparison CompareGeometryStage(
    const t::geometry::PointCloud& cloud, const camera::PinholeCamera& camera,
    const visualization::rendering::RenderConfig& config,
    const visualization::rendering::vulkan::GeometryStageReadback& gpu,
    const std::vector<bool>& hidden = {});

}  // namespace tests
}  // namespace open3d
