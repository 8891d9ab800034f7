#include "open3d/visualization/rendering/gaussian_splat/PlaceholderBackend.h"

#include <algorithm>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"

namespace open3d {
namespace visualization {
namespace rendering {

void PlaceholderBackend::SetScene(const t::geometry::PointCloud& cloud) {
    num_splats_ = cloud.NumPoints();
}

void PlaceholderBackend::RenderGeometryStage(const camera::PinholeCamera& camera,
                                             const RenderConfig& config) {
    camera.Validate();
    config.Validate();
    if (!logged_) {
        core::LogWarning(
            "Gaussian splat placeholder backend: {} splats are not drawn (no real backend)",
            num_splats_);
        logged_ = true;
    }
    camera_ = camera;
    config_ = config;
}

void PlaceholderBackend::RenderCompositeStage(RenderOutput& output, const CompositeInputs& inputs) {
    if (!camera_) core::ThrowError("RenderCompositeStage called before RenderGeometryStage");
    const int h = camera_->height, w = camera_->width;
    output.color = t::geometry::Image(h, w, 4, core::Dtype::Float32);
    for (int64_t p = 0; p < output.color.NumPixels(); ++p) {
        for (int c = 0; c < 3; ++c) {
            output.color.Data<float>()[p * 4 + c] = static_cast<float>(config_.background[c]);
        }
    }
    output.depth_expected = t::geometry::Image(h, w, 1, core::Dtype::Float32);
    output.depth_median = t::geometry::Image(h, w, 1, core::Dtype::Float32);
    // Nothing is drawn: no pixel shows a splat.
    output.splat_id = t::geometry::Image();
    if (inputs.splat_id) {
        output.splat_id = t::geometry::Image(h, w, 1, core::Dtype::Int32);
        std::fill_n(output.splat_id.Data<int32_t>(), output.splat_id.NumPixels(), -1);
    }
    output.stats = RenderStats{};
    output.stats.num_splats = num_splats_;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
