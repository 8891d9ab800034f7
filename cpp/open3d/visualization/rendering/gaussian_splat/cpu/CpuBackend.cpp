#include "open3d/visualization/rendering/gaussian_splat/cpu/CpuBackend.h"
#include "open3d/core/Timer.h"

#include <chrono>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Composite.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

void CpuBackend::SetScene(const t::geometry::PointCloud& cloud) {
    cloud.ValidateGaussianSplat();
    cloud_ = cloud;
    camera_.reset();
    projected_.clear();
    tile_lists_ = TileLists{};
}

void CpuBackend::ReleaseResources() {
    cloud_.reset();
    camera_.reset();
    // A fresh vector, not `= {}`: that assigns an empty initializer list and keeps the
    // capacity (a million splats' projections, 170 MB, stayed allocated).
    projected_ = std::vector<ProjectedSplat>();
    tile_lists_ = TileLists{};
}

void CpuBackend::RenderGeometryStage(const camera::PinholeCamera& camera,
                                     const RenderConfig& config) {
    if (!cloud_) core::ThrowError("cpu backend: RenderGeometryStage called before SetScene");
    config.Validate();
    const auto start = std::chrono::steady_clock::now();
    // The last view's results go first: they are replaced, and both would not fit twice.
    projected_ = std::vector<ProjectedSplat>();
    tile_lists_ = TileLists{};
    camera_.reset();
    const uint64_t n = static_cast<uint64_t>(cloud_->NumPoints());
    core::RequireHostMemory(n * (sizeof(ProjectedSplat) + 2 * sizeof(uint64_t)),
                            fmt::format("cpu backend: projecting {} splats", n),
                            "the vulkan backend keeps them in device memory");
    projected_ = ProjectSplats(*cloud_, camera, config);
    tile_lists_ =
        BuildTileLists(projected_, TileGrid::ForImage(camera.width, camera.height), config);
    camera_ = camera;
    config_ = config;
    geometry_ms_ = core::MillisecondsSince(start);
}

void CpuBackend::RenderCompositeStage(RenderOutput& output, const CompositeInputs& inputs) {
    if (!camera_)
        core::ThrowError("cpu backend: RenderCompositeStage called before the geometry stage");
    const auto start = std::chrono::steady_clock::now();
    CompositeTiles(projected_, tile_lists_, camera_->width, camera_->height, config_, inputs,
                   output);
    // The reference computes both depths alongside the colour; it returns what was asked for,
    // as the GPU backends do.
    if (!inputs.expected_depth) output.depth_expected = t::geometry::Image();
    if (!inputs.median_depth) output.depth_median = t::geometry::Image();
    output.stats = RenderStats{};
    output.stats.num_splats = static_cast<int64_t>(projected_.size());
    for (const ProjectedSplat& s : projected_) output.stats.num_visible += s.IsVisible() ? 1 : 0;
    output.stats.num_tile_entries = tile_lists_.NumEntries();
    output.stats.error_flags = tile_lists_.error_flags;
    output.stats.geometry_ms = geometry_ms_;
    output.stats.composite_ms = core::MillisecondsSince(start);
}

RenderOutput RenderReference(const t::geometry::PointCloud& cloud,
                             const camera::PinholeCamera& camera, const RenderConfig& config) {
    CpuBackend backend;
    backend.SetScene(cloud);
    return backend.Render(camera, config);
}

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
