#include "open3d/visualization/rendering/filament/OffscreenRenderer.h"

#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/filament/FilamentRenderer.h"

namespace open3d {
namespace visualization {
namespace rendering {

OffscreenRenderer::OffscreenRenderer(int width, int height, const Open3DSceneOptions& options)
    : width_(width), height_(height) {
    if (width <= 0 || height <= 0) {
        core::ThrowError("OffscreenRenderer: the size must be positive (got {} x {})", width,
                         height);
    }
    own_engine_ = std::make_unique<FilamentEngine>();
    engine_ = own_engine_.get();
    Build(options);
}

OffscreenRenderer::OffscreenRenderer(FilamentEngine& engine, int width, int height,
                                     const Open3DSceneOptions& options)
    : width_(width), height_(height), engine_(&engine) {
    if (width <= 0 || height <= 0) {
        core::ThrowError("OffscreenRenderer: the size must be positive (got {} x {})", width,
                         height);
    }
    Build(options);
}

void OffscreenRenderer::Build(const Open3DSceneOptions& options) {
    renderer_ = std::make_unique<FilamentRenderer>(*engine_);
    scene_ = std::make_unique<Open3DScene>(*renderer_, options);
    // Until a camera is set up: the scene's bounds (none yet) from the default distance.
    scene_->ResetCamera(width_, height_);
}

OffscreenRenderer::~OffscreenRenderer() {
    // Scene before renderer before engine: each holds objects of the next.
    scene_.reset();
    renderer_.reset();
    own_engine_.reset();
}

void OffscreenRenderer::SetupCamera(float vertical_fov_deg, const Eigen::Vector3f& center,
                                    const Eigen::Vector3f& eye, const Eigen::Vector3f& up) {
    camera::LookAtCamera look_at;
    look_at.center = center.cast<double>();
    look_at.eye = eye.cast<double>();
    look_at.up = up.cast<double>();
    look_at.vertical_fov_deg = vertical_fov_deg;
    scene_->SetupCamera(look_at, width_, height_);
}

void OffscreenRenderer::SetupCamera(const Eigen::Matrix3d& intrinsic,
                                    const Eigen::Matrix4d& extrinsic) {
    scene_->SetupCamera(
        camera::PinholeCamera::FromIntrinsic(intrinsic, extrinsic, width_, height_));
}

void OffscreenRenderer::SetupCamera(const camera::PinholeCamera& camera) {
    const bool same = camera.width == width_ && camera.height == height_;
    scene_->SetupCamera(same ? camera : camera.Resized(width_, height_));
}

t::geometry::Image OffscreenRenderer::RenderToImage() { return scene_->RenderToImage(false); }

t::geometry::Image OffscreenRenderer::RenderToDepthImage(bool z_in_view_space) {
    return scene_->RenderToDepthImage(z_in_view_space ? DepthFormat::kViewZ
                                                      : DepthFormat::kReversedZ);
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
