// The Open3D-style scene API on top of the Filament layer (docs/filament.md "Scene API"):
// named splat clouds and meshes, a background, a camera, and offscreen RenderToImage /
// RenderToDepthImage that run the whole frame (meshes, splat geometry and composite stages, the
// blend).
#pragma once

#include <Eigen/Core>

#include <memory>
#include <string>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/FilamentRenderer.h"
#include "open3d/visualization/rendering/filament/FilamentScene.h"
#include "open3d/visualization/rendering/filament/FilamentView.h"

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

class Open3DScene {
public:
    /// A scene drawn by `renderer`'s engine. Throws core::Open3DError when a named backend
    /// cannot be made.
    explicit Open3DScene(FilamentRenderer& renderer, const Open3DSceneOptions& options = {});
    ~Open3DScene();

    void AddGeometry(const std::string& name, const t::geometry::PointCloud& cloud);
    void AddGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh,
                     const MeshMaterial& material = {});
    void UpdateGeometry(const std::string& name, const t::geometry::PointCloud& cloud);
    void UpdateGeometry(const std::string& name, const t::geometry::TriangleMesh& mesh);
    bool RemoveGeometry(const std::string& name);
    void ShowGeometry(const std::string& name, bool show);
    bool HasGeometry(const std::string& name) const;
    void ClearGeometry();

    /// Linear RGBA where nothing is drawn (default opaque black).
    void SetBackground(const Eigen::Vector4f& rgba);
    /// Splat settings (SH degree cap, antialias, sort mode...); background is not used.
    RenderConfig& GetSplatConfig() { return splat_config_; }

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
    /// depth per pixel: Float32 [H, W, 1] view z in scene units (0 where nothing is), or
    /// with `normalized` UInt16 round(65535 * (z - near) / (far - near)), 65535 = nothing.
    t::geometry::Image RenderToDepthImage(bool normalized = false, float near = 0.2f,
                                          float far = 100.0f);

    /// The last frame's stats and times.
    const FrameResult& GetLastFrame() const { return last_frame_; }
    FilamentScene& GetScene() { return *scene_; }
    FilamentView& GetView() { return *view_; }

private:
    FilamentRenderer& renderer_;
    std::unique_ptr<FilamentScene> scene_;
    std::unique_ptr<FilamentView> view_;
    RenderConfig splat_config_;
    FrameResult last_frame_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
