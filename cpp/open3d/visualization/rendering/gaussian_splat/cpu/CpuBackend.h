// The CPU reference as a backend named "cpu": the oracle the GPU backends are measured
// against. Its intermediate results are public so each GPU stage can be compared alone.
#pragma once

#include <optional>
#include <vector>

#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Projection.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/TileLists.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace cpu {

class CpuBackend : public GaussianSplatBackend {
public:
    std::string GetName() const override { return "cpu"; }
    void SetScene(const t::geometry::PointCloud& cloud) override;
    void ReleaseResources() override;
    void RenderGeometryStage(const camera::PinholeCamera& camera,
                             const RenderConfig& config) override;
    void RenderCompositeStage(RenderOutput& output, const CompositeInputs& inputs = {}) override;

    /// Geometry stage results of the last RenderGeometryStage (empty before the first).
    const std::vector<ProjectedSplat>& GetProjectedSplats() const { return projected_; }
    const TileLists& GetTileLists() const { return tile_lists_; }

private:
    std::optional<t::geometry::PointCloud> cloud_;
    std::optional<camera::PinholeCamera> camera_;
    RenderConfig config_;
    std::vector<ProjectedSplat> projected_;
    TileLists tile_lists_;
    double geometry_ms_ = 0.0;
};

/// One-call reference render of a cloud (both stages on a temporary CpuBackend).
RenderOutput RenderReference(const t::geometry::PointCloud& cloud,
                             const camera::PinholeCamera& camera, const RenderConfig& config = {});

}  // namespace cpu
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
