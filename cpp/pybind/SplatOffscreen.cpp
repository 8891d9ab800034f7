#include "SplatOffscreen.h"

#include <pybind11/pybind11.h>

#include <algorithm>

#include "open3d/core/Exception.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

namespace {

using visualization::rendering::MaterialRecord;
using visualization::rendering::RenderConfig;
using visualization::rendering::RenderOutput;

constexpr uint64_t kView = 0;  // the renderer's one view

}  // namespace

SplatOffscreen::SplatOffscreen(int width, int height, const std::string& backend, bool meshes)
    : width_(width), height_(height) {
    if (width <= 0 || height <= 0) {
        core::ThrowError("OffscreenRenderer: size must be positive, got {}x{}", width, height);
    }
    if (backend != "vulkan" && backend != "cpu") {
        core::ThrowError("OffscreenRenderer: backend '{}' (vulkan or cpu)", backend);
    }
    if (!meshes) {
        renderer_ = std::make_unique<visualization::rendering::GaussianSplatRenderer>(backend);
        return;
    }
    visualization::rendering::Open3DSceneOptions options;
    options.backend = backend;
    try {
        filament_ =
            std::make_unique<visualization::rendering::OffscreenRenderer>(width, height, options);
    } catch (const core::Open3DError& e) {
        core::ThrowError(
            "OffscreenRenderer(meshes=True) draws with Filament, which needs an X server or, "
            "headless, an EGL display with OpenGL 4.5 (splats alone need neither: leave "
            "meshes off): {}",
            e.what());
    }
}

std::string SplatOffscreen::BackendName() const {
    return filament_ ? filament_->GetScene()->GetScene().GetBackend().GetName()
                     : renderer_->GetBackendName();
}

void SplatOffscreen::AddCloud(const std::string& name, const t::geometry::PointCloud& cloud,
                              const std::optional<MaterialRecord>& material) {
    if (filament_) {
        if (material) {
            filament_->GetScene()->AddGeometry(name, cloud, *material);
        } else {
            filament_->GetScene()->AddGeometry(name, cloud);
        }
    } else {
        if (material && material->shader != visualization::rendering::kShaderGaussianSplat) {
            core::ThrowError(
                "OffscreenRenderer: '{}' with shader '{}': a renderer without meshes=True draws "
                "Gaussian splat clouds only; set material.shader = 'gaussianSplat' (or leave "
                "it unset) to draw the cloud as splats, or create the renderer with "
                "meshes=True to draw points",
                name, material->shader);
        }
        renderer_->AddCloud(name, cloud);
    }
    names_.push_back(name);
}

void SplatOffscreen::AddMesh(const std::string& name, const t::geometry::TriangleMesh& mesh,
                             const MaterialRecord& material) {
    if (!filament_) {
        core::ThrowError(
            "OffscreenRenderer: mesh '{}': meshes are drawn by Filament; create the renderer "
            "with meshes=True (Filament: an X server, or EGL without one)",
            name);
    }
    filament_->GetScene()->AddGeometry(name, mesh, material);
    names_.push_back(name);
}

void SplatOffscreen::UpdateCloud(const std::string& name, const t::geometry::PointCloud& cloud) {
    if (filament_) {
        filament_->GetScene()->UpdateGeometry(name, cloud);
    } else {
        renderer_->UpdateCloud(name, cloud);
    }
}

bool SplatOffscreen::Remove(const std::string& name) {
    const bool removed =
        filament_ ? filament_->GetScene()->RemoveGeometry(name) : renderer_->RemoveCloud(name);
    std::erase(names_, name);
    return removed;
}

void SplatOffscreen::Show(const std::string& name, bool show) {
    if (filament_) {
        filament_->GetScene()->ShowGeometry(name, show);
    } else {
        renderer_->ShowCloud(name, show);
    }
}

bool SplatOffscreen::Has(const std::string& name) const {
    return filament_ ? filament_->GetScene()->HasGeometry(name) : renderer_->HasCloud(name);
}

void SplatOffscreen::Clear() {
    if (filament_) {
        filament_->GetScene()->ClearGeometry();
    } else {
        renderer_->Clear();
    }
    names_.clear();
}

visualization::rendering::GaussianSplatRenderer& SplatOffscreen::SplatRenderer() const {
    return filament_ ? filament_->GetScene()->GetScene().GetSplatRenderer() : *renderer_;
}

void SplatOffscreen::SetBackground(const Eigen::Vector3d& rgb) {
    config_.background = rgb;
    if (filament_) filament_->GetScene()->SetBackground(rgb.cast<float>().homogeneous());
}

void SplatOffscreen::SetCamera(const camera::PinholeCamera& camera, bool rescale) {
    camera_ = Sized(camera, rescale, "setup_camera: the camera");
    has_camera_ = true;
}

const camera::PinholeCamera& SplatOffscreen::Camera() const {
    if (!has_camera_) core::ThrowError("OffscreenRenderer: call setup_camera first");
    return camera_;
}

RenderOutput SplatOffscreen::Render(bool expected_depth, bool median_depth, bool splat_id) {
    const camera::PinholeCamera camera = Camera();
    RequireVisibleSplats();
    RenderOutput out;
    visualization::rendering::CompositeInputs inputs;
    inputs.expected_depth = expected_depth;
    inputs.median_depth = median_depth;
    inputs.splat_id = splat_id;
    py::gil_scoped_release release;
    renderer_->Prepare();
    renderer_->RenderGeometryStage(kView, camera, config_);
    renderer_->RenderCompositeStage(kView, out, inputs);
    return out;
}

t::geometry::Image SplatOffscreen::RenderSplatId() {
    if (filament_) {
        core::ThrowError(
            "render_to_id_image: splat-only renderers (meshes=False); a mesh has no splat ID");
    }
    if (renderer_->IsStreaming()) {
        core::ThrowError("render_to_id_image: not while a stream runs (its IDs are pool slots)");
    }
    return Render(false, false, true).splat_id;  // a member of the temporary: moved
}

t::geometry::Image SplatOffscreen::RenderWithMeshes(bool depth) {
    const camera::PinholeCamera camera = Camera();
    // The knobs go to the scene's splat settings (background stays the view's).
    RenderConfig& splat = filament_->GetScene()->GetSplatConfig();
    splat.sh_degree = config_.sh_degree;
    splat.antialias = config_.antialias;
    splat.near_plane = config_.near_plane;
    splat.compact_storage = config_.compact_storage;
    filament_->SetupCamera(camera);
    py::gil_scoped_release release;
    return depth ? filament_->RenderToDepthImage(true) : filament_->RenderToImage();
}

void SplatOffscreen::RenderBatch(const std::vector<camera::PinholeCamera>& cameras, bool rescale,
                                 bool uint8, uint8_t* destination,
                                 const visualization::rendering::BatchHostMemory& memory) {
    if (filament_) {
        core::ThrowError("render_batch: batches are for splat-only renderers (meshes=False)");
    }
    if (renderer_->IsStreaming()) {
        // A batch draws the pool as it stands and gives the stream no view.
        core::ThrowError(
            "render_batch: not while a stream runs (render_to_image streams for its view)");
    }
    std::vector<camera::PinholeCamera> sized;
    for (size_t i = 0; i < cameras.size(); ++i) {
        sized.push_back(Sized(cameras[i], rescale, fmt::format("render_batch: camera {}", i)));
    }
    RequireVisibleSplats();
    visualization::rendering::BatchOptions options;
    options.color_uint8 = uint8;
    options.color_destination = destination;
    options.color_memory = memory;
    py::gil_scoped_release release;
    renderer_->Prepare();
    // The batch replaces the view's sorted entries in the backend.
    renderer_->ReleaseView(kView);
    renderer_->GetBackend().RenderBatch(sized, config_, options);
}

camera::PinholeCamera SplatOffscreen::Sized(const camera::PinholeCamera& camera, bool rescale,
                                            const std::string& what) const {
    camera.Validate();
    if (camera.width == width_ && camera.height == height_) return camera;
    if (!rescale) {
        core::ThrowError(
            "{} is {}x{}, the renderer's picture {}x{}: pass rescale=True to scale its "
            "intrinsics to {}x{} (another aspect ratio stretches the picture), or make the "
            "renderer {}x{}",
            what, camera.width, camera.height, width_, height_, width_, height_, camera.width,
            camera.height);
    }
    return camera.Resized(width_, height_);
}

void SplatOffscreen::RequireVisibleSplats() const {
    if (!renderer_->HasVisibleSplats()) {
        core::ThrowError("OffscreenRenderer: the scene has no visible splat cloud");
    }
}

}  // namespace pybind
}  // namespace open3d
