// A backend that draws nothing (transparent background, zero depth) and says so once per
// instance, i.e. once per view that owns it: used where no real backend is available.
#pragma once

#include <optional>

#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"

namespace open3d {
namespace visualization {
namespace rendering {

class PlaceholderBackend : public GaussianSplatBackend {
public:
    std::string GetName() const override { return "placeholder"; }
    void SetScene(const t::geometry::PointCloud& cloud) override;
    void ReleaseResources() override { camera_.reset(); }
    void RenderGeometryStage(const camera::PinholeCamera& camera,
                             const RenderConfig& config) override;
    void RenderCompositeStage(RenderOutput& output, const CompositeInputs& inputs = {}) override;

private:
    bool logged_ = false;
    int64_t num_splats_ = 0;
    std::optional<camera::PinholeCamera> camera_;
    RenderConfig config_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
