// The Open3D-style scene API on top of the Filament layer (docs/filament.md "Scene API"):
// named geometries drawn by their MaterialRecord (Gaussian splat clouds, plain point clouds,
// lit or unlit meshes), a background, a camera, and offscreen RenderToImage /
// RenderToDepthImage that run the whole frame (meshes and points, the splat geometry and
// composite stages, the blend). Its view is added to the renderer, so the renderer's
// BeginFrame runs its geometry stage.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <string>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/FilamentRenderer.h"
#include "open3d/visualization/rendering/filament/FilamentScene.h"
#include "open3d/visualization/rendering/filament/FilamentView.h"
#include "open3d/visualization/rendering/filament/MaterialRecord.h"

namespace open3d {
namespace visualization {
namespace rendering {

struct Open3DSceneOptions {
    /// Splat backend: "auto" = "vulkan" where a device exists, else "placeholder" (draws no
    /// splats, says so once); or any registered name ("vulkan", "cpu", ...).
    std::string backend = "auto";
    /// How splat images reach Filament; env OPEN3D_SPLAT_SHARING (auto, zero-copy,
    /// host-copy) overrides kAuto.
    SplatSharing sharing = SplatSharing::kAuto;
};

/// What RenderToDepthImage returns.
enum class DepthFormat {
    /// Float32 [H, W, 1] view-space z in scene units, 0 where nothing is.
    kViewZ,
    /// UInt16 [H, W, 1] round(65535 * (z - near) / (far - near)), 65535 where nothing is.
    kNormalized16,
    /// Float32 [H, W, 1] Filament's reversed-Z depth of an infinite projection: near / z,
    /// 1 at the near plane, 0 where nothing is.
    kReversedZ
};

class Open3DScene {
public:
    /// A scene drawn by `renderer`'s engine. Throws core::Open3DError when a named backend
    /// cannot be made.
    explicit Open3DScene(FilamentRenderer& renderer, const Open3DSceneOptions& options = {});
    ~Open3DScene();

    /// A point cloud: with the Gaussian attributes it is drawn as splats, otherwise as
    /// points (MaterialRecord's defaults).
    void AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud);
    /// A point cloud drawn by `material.shader`: "gaussianSplat" (needs the Gaussian
    /// attributes; its SH degree and antialias fields become the scene's splat settings) or
    /// "defaultUnlit" / "defaultLit" (points of `point_size` pixels).
    void AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud,
                     const MaterialRecord& material);
    /// A triangle mesh, "defaultUnlit" or "defaultLit".
    void AddGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh,
                     const MaterialRecord& material = {});
    void UpdateGeometry(const std::string& name, const t::geometry::PointCloud& cloud);
    void UpdateGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh);
    bool RemoveGeometry(const std::string& name);
    void ShowGeometry(const std::string& name, bool show);
    bool HasGeometry(const std::string& name) const;
    void ClearGeometry();

    /// Linear RGBA where nothing is drawn (default opaque black).
    void SetBackground(const Eigen::Vector4f& rgba);
    /// Splat settings (SH degree cap, antialias, sort mode...); background is not used.
    RenderConfig& GetSplatConfig() { return view_->GetSplatConfig(); }
    /// The directional light of "defaultLit" meshes (direction from the light into the
    /// scene, in the world frame or the camera's: FilamentScene::SetLighting) and the
    /// ambient term in [0, 1]. Default: a headlight from above left behind the camera.
    void SetLighting(const Eigen::Vector3f& direction, float ambient,
                     FilamentScene::LightFrame frame = FilamentScene::LightFrame::kWorld);

    /// The camera and the image size of the renders.
    void SetupCamera(const camera::PinholeCamera& camera);
    void SetupCamera(const camera::LookAtCamera& look_at, int width, int height);
    /// View `index` of a 3DGS cameras.json, scaled to width x height (0: the file's size).
    void SetupCameraFromJson(const std::string& cameras_json, int index, int width = 0,
                             int height = 0);
    /// Looks along +z at the centre of the visible geometry's bounds, with world -y up in
    /// the image (the OpenCV / COLMAP convention of 3DGS scenes; the identity extrinsic's
    /// orientation), far enough that the bounding sphere fits the vertical field of view.
    void ResetCamera(int width, int height, double vertical_fov_deg = 60.0);
    const camera::PinholeCamera& GetCamera() const { return view_->GetCamera(); }

    /// UInt8 [H, W, 3] (or [H, W, 4] with alpha): splats blended over the meshes and the
    /// background, top row first.
    t::geometry::Image RenderToImage(bool with_alpha = false);
    /// The nearer of the splat depth (expected depth where coverage >= 0.5) and the mesh
    /// depth per pixel, in `format`. `near` / `far` default to the view's (its mesh near
    /// plane, 0.01 unless set, and its far plane); only kNormalized16 uses `far`.
    t::geometry::Image RenderToDepthImage(DepthFormat format = DepthFormat::kViewZ,
                                          std::optional<float> near = std::nullopt,
                                          std::optional<float> far = std::nullopt);
    /// The near and far planes of the view (FilamentView::SetMeshNearPlane / SetFarPlane).
    void SetClipPlanes(double near, double far);

    /// The last frame's stats and times.
    const FrameResult& GetLastFrame() const { return last_frame_; }
    FilamentScene& GetScene() { return *scene_; }
    FilamentView& GetView() { return *view_; }

private:
    FilamentRenderer& renderer_;
    std::unique_ptr<FilamentScene> scene_;
    std::unique_ptr<FilamentView> view_;
    FrameResult last_frame_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
