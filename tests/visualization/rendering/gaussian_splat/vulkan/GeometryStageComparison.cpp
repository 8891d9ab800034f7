#include "GeometryStageComparison.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

namespace open3d {
namespace tests {

namespace {

// shader::TileRowSpan of row ty on the GPU's own stored record (the emit pass's inputs).
uint32_t GpuRowSpan(const visualization::rendering::shader::GaussianProjectedSplat& g,
                    uint32_t ty) {
    return visualization::rendering::shader::TileRowSpan(
        g.center_x, g.center_y, g.conic.x, g.conic.y, g.conic.z, g.det_q, g.cull_threshold, ty,
        g.rect_min & 0xFFFFu, g.rect_max & 0xFFFFu);
}

using visualization::rendering::kTileSize;
using visualization::rendering::RenderConfig;
using namespace visualization::rendering::cpu;
namespace shader = visualization::rendering::shader;

// Distances in pixels below which a float32 computation may land on the other
// side of a decision the double reference took. The GPU centre differs from the
// reference by a few 1e-5 px on these scenes (ProjectionErrors::center_px) and
// the radius argument by a few 1e-6 relative; 1e-3 px / 1e-4 relative leave two
// orders of margin while still calling almost every splat "clearly decided".
constexpr double kBorderPx = 1e-3;
constexpr double kRadiusRel = 1e-4;

double FracDistance(double v) { return std::abs(v - std::round(v)); }

// True when ceil(3 sqrt(lambda_max)) of the reference sits within rounding of
// an integer.
bool RadiusNearInteger(const ProjectedSplat& s) {
    const double det = s.cov_a * s.cov_c - s.cov_b * s.cov_b;
    const double mid = 0.5 * (s.cov_a + s.cov_c);
    const double three_sigma = 3.0 * std::sqrt(mid + std::sqrt(std::max(0.1, mid * mid - det)));
    return FracDistance(three_sigma) < kRadiusRel * std::max(1.0, three_sigma);
}

// True when a tile bound of the reference rect (for radius r) sits within
// kBorderPx of a tile edge, or the centre is near the near plane.
bool RectNearBorder(const ProjectedSplat& s, int r) {
    for (double v : {s.x - r, s.y - r, s.x + r + kTileSize - 1, s.y + r + kTileSize - 1}) {
        if (FracDistance(v / kTileSize) * kTileSize < kBorderPx) return true;
    }
    return false;
}

bool DecisionNearBorder(const ProjectedSplat& s, const RenderConfig& config, int gpu_radius) {
    if (std::abs(s.depth - config.near_plane) < 1e-6 * std::max(1.0, config.near_plane))
        return true;
    if (s.cull == CullReason::kNearPlane || s.cull == CullReason::kDegenerate) return false;
    return RadiusNearInteger(s) || RectNearBorder(s, s.radius) ||
           (gpu_radius > 0 && RectNearBorder(s, gpu_radius));
}

using OrderKey = std::pair<float, uint32_t>;  // (float32 depth, splat index)

}  // namespace

std::string GeometryStageComparison::Summary() const {
    return fmt::format(
        "splats {} visible cpu/gpu {}/{} cull flips {} (unexplained {}) | max err: centre "
        "{:.3g} px, depth {:.3g} rel, conic {:.3g} rel, opacity {:.3g}, colour {:.3g}; radius "
        "+-1 {} (more {}), rect differs {}, span differs {} | entries cpu/gpu {}/{}, border "
        "splats {} (entries {}), tiles misordered {}, gpu span mismatches {}, depth-rounding "
        "swaps {} (max gap {:.3g} rel), visible list misordered {}",
        num_splats, visible_cpu, visible_gpu, cull_flips, cull_flips_unexplained, errors.center_px,
        errors.depth_rel, errors.conic_rel, errors.opacity_abs, errors.color_abs,
        errors.radius_off_by_one, errors.radius_off_more, errors.rect_differs, errors.span_differs,
        entries_cpu, entries_gpu, border_splats.size(), border_entries, tiles_misordered,
        gpu_span_mismatches, depth_rounding_swaps, depth_rounding_swap_max_rel,
        visible_list_misordered);
}

GeometryStageComparison CompareGeometryStage(
    const t::geometry::PointCloud& cloud, const camera::PinholeCamera& camera,
    const RenderConfig& config, const visualization::rendering::vulkan::GeometryStageReadback& gpu,
    const std::vector<bool>& hidden) {
    GeometryStageComparison c;
    std::vector<ProjectedSplat> ref = ProjectSplats(cloud, camera, config);
    const size_t n = ref.size();
    c.num_splats = static_cast<int64_t>(n);
    for (size_t i = 0; i < hidden.size() && i < n; ++i) {
        if (hidden[i]) ref[i].cull = CullReason::kNearPlane;  // the reference's "emits nothing"
    }
    std::vector<bool> gpu_visible(n, false);
    for (uint32_t i : gpu.visible_in_depth_order) gpu_visible.at(i) = true;
    c.visible_gpu = static_cast<int64_t>(gpu.visible_in_depth_order.size());

    std::set<uint32_t> border;
    for (size_t i = 0; i < n; ++i) {
        const ProjectedSplat& r = ref[i];
        c.visible_cpu += r.IsVisible();
        const shader::GaussianProjectedSplat* g = gpu_visible[i] ? &gpu.projected.at(i) : nullptr;
        const int gpu_radius = g ? static_cast<int>(g->radius) : 0;
        if (r.IsVisible() != gpu_visible[i]) {
            ++c.cull_flips;
            if (!DecisionNearBorder(r, config, gpu_radius)) ++c.cull_flips_unexplained;
            border.insert(static_cast<uint32_t>(i));
            continue;
        }
        if (!g) continue;
        ProjectionErrors& e = c.errors;
        e.center_px =
            std::max({e.center_px, std::abs(g->center_x - r.x), std::abs(g->center_y - r.y)});
        e.depth_rel = std::max(e.depth_rel, std::abs(g->depth - r.depth) / r.depth);
        const double conic_scale = std::max(std::abs(r.conic_a), std::abs(r.conic_c));
        e.conic_rel = std::max({e.conic_rel, std::abs(g->conic.x - r.conic_a) / conic_scale,
                                std::abs(g->conic.y - r.conic_b) / conic_scale,
                                std::abs(g->conic.z - r.conic_c) / conic_scale});
        e.opacity_abs = std::max(e.opacity_abs, std::abs(g->opacity - r.opacity));
        e.color_abs =
            std::max({e.color_abs, std::abs(g->color.x - r.color[0]),
                      std::abs(g->color.y - r.color[1]), std::abs(g->color.z - r.color[2])});
        const int dr = std::abs(gpu_radius - r.radius);
        if (dr == 1) ++e.radius_off_by_one;
        if (dr > 1) ++e.radius_off_more;
        const uint32_t min_packed = uint32_t(r.rect_min_x) | (uint32_t(r.rect_min_y) << 16);
        const uint32_t max_packed = uint32_t(r.rect_max_x) | (uint32_t(r.rect_max_y) << 16);
        if (g->rect_min != min_packed || g->rect_max != max_packed) {
            ++e.rect_differs;
            if (!DecisionNearBorder(r, config, gpu_radius)) ++c.cull_flips_unexplained;
            border.insert(static_cast<uint32_t>(i));
            continue;
        }
        for (int ty = r.rect_min_y; ty < r.rect_max_y; ++ty) {
            const auto [first, last] = r.RowSpan(ty);
            const uint32_t span = GpuRowSpan(*g, uint32_t(ty));
            if (uint32_t(first) != (span & 0xFFFFu) || uint32_t(last) != (span >> 16)) {
                ++e.span_differs;
                border.insert(static_cast<uint32_t>(i));
                break;
            }
        }
    }
    c.border_splats.assign(border.begin(), border.end());

    // The order both sides must give: the reference's float32 order depth (which the GPU
    // computes bit for bit, RenderConfig::depth_order), then splat index. The record's z is
    // the camera-relative view z, which orders only in DepthOrder::kCameraRelative.
    const auto gpu_key = [&](uint32_t i) { return OrderKey{ref.at(i).sort_depth, i}; };
    for (size_t k = 1; k < gpu.visible_in_depth_order.size(); ++k) {
        if (!(gpu_key(gpu.visible_in_depth_order[k - 1]) <
              gpu_key(gpu.visible_in_depth_order[k]))) {
            ++c.visible_list_misordered;
        }
    }

    const TileGrid grid = TileGrid::ForImage(camera.width, camera.height);
    const TileLists lists = BuildTileLists(ref, grid, config);
    c.entries_cpu = lists.NumEntries();
    c.entries_gpu = static_cast<int64_t>(gpu.entry_tiles.size());
    std::vector<std::vector<uint32_t>> gpu_tiles(grid.NumTiles());
    std::vector<int64_t> gpu_entries_of(n, 0);
    for (size_t k = 0; k < gpu.entry_tiles.size(); ++k) {
        if (k > 0 && gpu.entry_tiles[k] < gpu.entry_tiles[k - 1]) ++c.tiles_misordered;
        if (gpu.entry_tiles[k] >= uint32_t(grid.NumTiles())) {  // gaussian_emit's filler
            ++c.gpu_span_mismatches;
            continue;
        }
        gpu_tiles.at(gpu.entry_tiles[k]).push_back(gpu.entry_splats[k]);
        ++gpu_entries_of.at(gpu.entry_splats[k]);
    }
    // Each emitting splat's GPU entries are exactly the spans of its own record.
    for (uint32_t i : gpu.visible_in_depth_order) {
        if (gpu_entries_of[i] == 0) continue;  // dropped by a limit, or no tile to emit
        const shader::GaussianProjectedSplat& g = gpu.projected.at(i);
        int64_t expected = 0;
        for (uint32_t ty = g.rect_min >> 16; ty < (g.rect_max >> 16); ++ty) {
            expected += shader::TileSpanCount(GpuRowSpan(g, ty));
        }
        if (expected != gpu_entries_of[i]) ++c.gpu_span_mismatches;
    }
    std::set<std::pair<uint32_t, uint32_t>> swapped_pairs;
    for (int64_t t = 0; t < grid.NumTiles(); ++t) {
        std::vector<uint32_t> expected, actual;
        for (uint64_t k = lists.offsets[t]; k < lists.offsets[t + 1]; ++k) {
            const uint32_t i = lists.splat_indices[k];
            if (border.count(i)) {
                ++c.border_entries;
            } else {
                expected.push_back(i);
            }
        }
        for (uint32_t i : gpu_tiles[t]) {
            if (border.count(i)) {
                ++c.border_entries;
            } else {
                actual.push_back(i);
            }
        }
        // Reference set in the GPU's order: must match exactly.
        std::vector<uint32_t> reordered = expected;
        std::sort(reordered.begin(), reordered.end(),
                  [&](uint32_t a, uint32_t b) { return gpu_key(a) < gpu_key(b); });
        if (reordered != actual) {
            ++c.tiles_misordered;
            continue;
        }
        // Where the GPU order differs from the reference's, the depths must be
        // rounding-close.
        if (actual != expected) {
            for (size_t k = 1; k < actual.size(); ++k) {
                const uint32_t a = actual[k - 1], b = actual[k];
                const OrderKey ka{float(ref[a].depth), a}, kb{float(ref[b].depth), b};
                if (kb < ka) {
                    swapped_pairs.insert({std::min(a, b), std::max(a, b)});
                    c.depth_rounding_swap_max_rel =
                        std::max(c.depth_rounding_swap_max_rel,
                                 std::abs(ref[a].depth - ref[b].depth) / ref[a].depth);
                }
            }
        }
    }
    c.depth_rounding_swaps = static_cast<int64_t>(swapped_pairs.size());
    return c;
}

}  // namespace tests
}  // namespace open3d
