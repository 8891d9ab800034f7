#include "open3d/visualization/rendering/filament/Open3DScene.h"

#include <cmath>
#include <cstdlib>

#include "open3d/camera/CamerasJson.h"
#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/filament/FilamentEngine.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanBackendRegistry.h"

namespace open3d {
namespace visualization {
namespace rendering {

namespace {

std::unique_ptr<GaussianSplatBackend> MakeBackend(const std::string& name) {
    vulkan::RegisterVulkanBackend();
    if (name != "auto") return CreateGaussianSplatBackend(name);
    try {
        return CreateGaussianSplatBackend("vulkan");
    } catch (const core::Open3DError& e) {
        core::LogWarning("No Vulkan device for Gaussian splats ({}); splats are not drawn",
                         e.what());
        return CreateGaussianSplatBackend("placeholder");
    }
}

SplatSharing SharingFromEnvironment(SplatSharing requested) {
    const char* env = std::getenv("OPEN3D_SPLAT_SHARING");
    if (requested != SplatSharing::kAuto || env == nullptr || env[0] == '\0') return requested;
    return ParseSplatSharing(env);
}

}  // namespace

Open3DScene::Open3DScene(FilamentRenderer& renderer, const Open3DSceneOptions& options)
    : renderer_(renderer) {
    scene_ = std::make_unique<FilamentScene>(renderer.GetEngine().GetEngine(),
                                             renderer.GetMaterials(), MakeBackend(options.backend));
    view_ = std::make_unique<FilamentView>(renderer.GetEngine(), renderer.GetMaterials(),
                                           SharingFromEnvironment(options.sharing));
}

Open3DScene::~Open3DScene() {
    // The view's targets belong to the scene's backend: they go first.
    view_.reset();
    scene_.reset();
}

void Open3DScene::AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud) {
    scene_->AddGeometry(name, cloud);
}
void Open3DScene::AddGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh,
                              const MeshMaterial& material) {
    scene_->AddGeometry(name, mesh, material);
}
void Open3DScene::UpdateGeometry(const std::string& name, const t::geometry::PointCloud& cloud) {
    scene_->UpdateGeometry(name, cloud);
}
void Open3DScene::UpdateGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh) {
    scene_->UpdateGeometry(name, mesh);
}
bool Open3DScene::RemoveGeometry(const std::string& name) { return scene_->RemoveGeometry(name); }
void Open3DScene::ShowGeometry(const std::string& name, bool show) {
    scene_->ShowGeometry(name, show);
}
bool Open3DScene::HasGeometry(const std::string& name) const { return scene_->HasGeometry(name); }
void Open3DScene::ClearGeometry() { scene_->ClearGeometry(); }
void Open3DScene::SetBackground(const Eigen::Vector4f& rgba) { view_->SetBackground(rgba); }

void Open3DScene::SetupCamera(const camera::PinholeCamera& camera) { view_->SetCamera(camera); }

void Open3DScene::SetupCamera(const camera::LookAtCamera& look_at, int width, int height) {
    view_->SetCamera(camera::PinholeCamera::FromLookAt(look_at, width, height));
}

void Open3DScene::SetupCameraFromJson(const std::string& cameras_json, int index, int width,
                                      int height) {
    const std::vector<camera::CameraView> views = camera::ReadCamerasJson(cameras_json);
    if (index < 0 || index >= static_cast<int>(views.size())) {
        core::ThrowError("{}: no view {} (the file has {} views)", cameras_json, index,
                         views.size());
    }
    camera::PinholeCamera camera = views[index].camera;
    if (width > 0 && height > 0) camera = camera.Resized(width, height);
    view_->SetCamera(camera);
}

void Open3DScene::ResetCamera(int width, int height, double vertical_fov_deg) {
    Eigen::Vector3d lo, hi;
    if (!scene_->GetBounds(lo, hi)) {
        lo = Eigen::Vector3d::Constant(-1.0);
        hi = Eigen::Vector3d::Constant(1.0);
    }
    const Eigen::Vector3d center = 0.5 * (lo + hi);
    const double radius = std::max(0.5 * (hi - lo).norm(), 1e-6);
    const double pi = std::acos(-1.0);
    const double half_fov = 0.5 * vertical_fov_deg * pi / 180.0;
    camera::LookAtCamera look_at;
    look_at.center = center;
    look_at.eye = center - Eigen::Vector3d(0, 0, radius / std::sin(half_fov));
    look_at.up = Eigen::Vector3d(0, -1, 0);  // OpenCV: y down in the image
    look_at.vertical_fov_deg = vertical_fov_deg;
    view_->SetCamera(camera::PinholeCamera::FromLookAt(look_at, width, height));
}

t::geometry::Image Open3DScene::RenderToImage(bool with_alpha) {
    FrameRequest request;
    request.splat_config = splat_config_;
    request.read_color = true;
    last_frame_ = renderer_.Draw(*scene_, *view_, request);
    return with_alpha ? last_frame_.color : last_frame_.color.SelectChannels(0, 3);
}

t::geometry::Image Open3DScene::RenderToDepthImage(bool normalized, float near, float far) {
    if (!(far > near))
        core::ThrowError("RenderToDepthImage: far ({}) must exceed near ({})", far, near);
    FrameRequest request;
    request.splat_config = splat_config_;
    request.read_depth = true;
    request.depth_near = near;
    request.depth_far = far;
    last_frame_ = renderer_.Draw(*scene_, *view_, request);
    return normalized ? last_frame_.normalized_depth : last_frame_.linear_depth;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
