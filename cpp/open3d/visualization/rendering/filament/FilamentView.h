// One view of a FilamentScene (docs/filament.md "Frame"): the mesh view, which renders the
// scene's meshes into a colour texture and the shared scene depth, and the compose view,
// which copies that colour to the screen and blends the splat overlay over it. Size-
// dependent objects (render target, splat targets) are made on first use and torn down
// before a resize frees anything they point to. MSAA stays off: the depth must be sampled.
#pragma once

#include <Eigen/Core>

#include <memory>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/visualization/rendering/filament/SplatTargets.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace filament {
class Camera;
class MaterialInstance;
class RenderTarget;
class Scene;
class Texture;
class View;
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

class FilamentEngine;
class FilamentMaterials;
class FilamentScene;

class FilamentView {
public:
    FilamentView(FilamentEngine& engine, const FilamentMaterials& materials, SplatSharing sharing);
    ~FilamentView();
    FilamentView(const FilamentView&) = delete;
    FilamentView& operator=(const FilamentView&) = delete;

    /// The camera and the view size (camera.width x camera.height). A new size releases
    /// the size-dependent targets first.
    void SetCamera(const camera::PinholeCamera& camera);
    const camera::PinholeCamera& GetCamera() const { return camera_; }
    /// Size the compose view covers on the swap chain; 0 x 0 (the default): the camera's.
    /// Larger than the camera, the picture is scaled up (nearest texel): the viewer draws
    /// frames at a reduced resolution while the camera moves on a slow device.
    void SetPresentSize(int width, int height) {
        present_width_ = width;
        present_height_ = height;
    }
    int GetPresentWidth() const { return present_width_ > 0 ? present_width_ : camera_.width; }
    int GetPresentHeight() const { return present_height_ > 0 ? present_height_ : camera_.height; }
    /// Near plane of the mesh projection (meshes closer are clipped); default 0.01. The
    /// projection has no far plane (Filament's depth is near / z).
    void SetMeshNearPlane(double near) { mesh_near_ = near; }
    double GetMeshNearPlane() const { return mesh_near_; }
    /// Far end of the normalised depth images (default 1000; Open3DScene::ResetCamera sets
    /// it to just past the scene's bounds). Nothing is clipped there.
    void SetFarPlane(double far) { far_ = far; }
    double GetFarPlane() const { return far_; }
    /// Splat settings of this view (SH degree cap, antialias, sort mode...); `background`
    /// is not used: the view's background shows through.
    RenderConfig& GetSplatConfig() { return splat_config_; }
    const RenderConfig& GetSplatConfig() const { return splat_config_; }
    /// Linear RGBA where nothing is drawn.
    void SetBackground(const Eigen::Vector4f& rgba) { background_ = rgba; }
    const Eigen::Vector4f& GetBackground() const { return background_; }

    /// Destroys the render target and the splat targets (call before the window or the
    /// swap chain they are drawn to is resized or destroyed).
    void ReleaseTargets();
    /// Makes the targets for the current size and binds `scene` to the mesh view.
    void PrepareTargets(FilamentScene& scene);

    filament::View* GetMeshView() const { return mesh_view_; }
    filament::View* GetComposeView() const { return compose_view_; }
    /// Null until PrepareTargets.
    SplatTargets* GetSplatTargets() const { return splat_targets_.get(); }
    filament::RenderTarget* GetMeshTarget() const { return mesh_target_; }
    /// Draws the overlay quad in the compose view or not (no visible splats).
    void SetOverlayVisible(bool visible);
    /// Times the targets were (re)made, for resize tests.
    int64_t GetTargetBuilds() const { return target_builds_; }

private:
    FilamentEngine& engine_;
    const FilamentMaterials& materials_;
    SplatSharing sharing_;
    camera::PinholeCamera camera_;
    int present_width_ = 0, present_height_ = 0;
    double mesh_near_ = 0.01;
    double far_ = 1000.0;
    RenderConfig splat_config_;
    Eigen::Vector4f background_{0.0f, 0.0f, 0.0f, 1.0f};

    filament::View* mesh_view_ = nullptr;
    filament::Camera* mesh_camera_ = nullptr;
    filament::View* compose_view_ = nullptr;
    filament::Scene* compose_scene_ = nullptr;
    filament::Camera* compose_camera_ = nullptr;
    uint32_t blit_entity_ = 0, overlay_entity_ = 0;  // utils::Entity ids
    filament::MaterialInstance* blit_material_ = nullptr;
    filament::MaterialInstance* overlay_material_ = nullptr;
    bool overlay_visible_ = false;

    // Size-dependent.
    const GaussianSplatBackend* targets_backend_ = nullptr;
    std::unique_ptr<SplatTargets> splat_targets_;
    filament::Texture* mesh_color_ = nullptr;
    filament::RenderTarget* mesh_target_ = nullptr;
    int64_t target_builds_ = 0;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
