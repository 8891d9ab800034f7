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
    return ResolveGaussianSplatBackend(name);
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
    renderer_.AddView(*scene_, *view_);
}

Open3DScene::~Open3DScene() {
    renderer_.RemoveView(*view_);
    // The view's targets belong to the scene's backend: they go first.
    view_.reset();
    scene_.reset();
}

void Open3DScene::AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud) {
    scene_->AddGeometry(name, cloud);
}
void Open3DScene::AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud,
                              const MaterialRecord& material) {
    scene_->AddGeometry(name, cloud, material);
    if (material.shader != kShaderGaussianSplat) return;
    RenderConfig& config = view_->GetSplatConfig();
    const bool differs = config.sh_degree != material.gaussian_splat_sh_degree ||
                         config.antialias != material.gaussian_splat_antialias;
    if (differs && scene_->GetSplatRenderer().GetCloudNames().size() > 1) {
        // The merged scene renders with one setting.
        core::LogWarning(
            "'{}': gaussianSplat SH degree {} / antialias {} now apply to every splat cloud "
            "of the scene",
            name, material.gaussian_splat_sh_degree, material.gaussian_splat_antialias);
    }
    config.sh_degree = material.gaussian_splat_sh_degree;
    config.antialias = material.gaussian_splat_antialias;
}
void Open3DScene::AddGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh,
                              const MaterialRecord& material) {
    scene_->AddGeometry(name, mesh, material);
}
void Open3DScene::SetLighting(const Eigen::Vector3f& direction, float ambient,
                              FilamentScene::LightFrame frame) {
    scene_->SetLighting(direction, ambient, frame);
}
void Open3DScene::SetClipPlanes(double near, double far) {
    if (!(near > 0.0) || !(far > near)) {
        core::ThrowError("SetClipPlanes: need 0 < near < far (got {}, {})", near, far);
    }
    view_->SetMeshNearPlane(near);
    view_->SetFarPlane(far);
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
    view_->SetFarPlane(radius / std::sin(half_fov) + radius);
}

t::geometry::Image Open3DScene::RenderToImage(bool with_alpha) {
    FrameRequest request;
    request.read_color = true;
    last_frame_ = renderer_.Draw(*scene_, *view_, request);
    return with_alpha ? last_frame_.color : last_frame_.color.SelectChannels(0, 3);
}

t::geometry::Image Open3DScene::RenderToDepthImage(DepthFormat format, std::optional<float> near,
                                                   std::optional<float> far) {
    const float n = near.value_or(static_cast<float>(view_->GetMeshNearPlane()));
    const float f = far.value_or(static_cast<float>(view_->GetFarPlane()));
    if (!(n > 0.0f) || !(f > n)) {
        core::ThrowError("RenderToDepthImage: need 0 < near < far (got near {}, far {})", n, f);
    }
    FrameRequest request;
    request.read_depth = true;
    request.depth_near = n;
    request.depth_far = f;
    last_frame_ = renderer_.Draw(*scene_, *view_, request);
    if (format == DepthFormat::kNormalized16) return last_frame_.normalized_depth;
    if (format == DepthFormat::kViewZ) return last_frame_.linear_depth;
    // Filament's convention for its infinite reversed-Z projection: d = near / z.
    const t::geometry::Image& z = last_frame_.linear_depth;
    t::geometry::Image reversed(z.GetRows(), z.GetCols(), 1, core::Dtype::Float32);
    const float* in = z.Data<float>();
    float* out = reversed.Data<float>();
    for (int64_t i = 0; i < z.GetRows() * z.GetCols(); ++i)
        out[i] = in[i] > 0.0f ? n / in[i] : 0.0f;
    return reversed;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
