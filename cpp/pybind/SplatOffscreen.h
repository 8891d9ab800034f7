// The state behind Python's OffscreenRenderer and its `scene`: the geometry, the camera and
// the settings. Without meshes the splat backend alone draws (GaussianSplatRenderer, no
// display needed); with `meshes` Filament's OffscreenRenderer does (meshes and splats
// composited by depth; GLX or headless EGL). Python's OffscreenRenderer and its Scene share
// one of these through a shared_ptr.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/MaterialRecord.h"
#include "open3d/visualization/rendering/filament/OffscreenRenderer.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatRenderer.h"

namespace open3d {
namespace pybind {

class SplatOffscreen {
public:
    SplatOffscreen(int width, int height, const std::string& backend, bool meshes);

    bool HasMeshes() const { return filament_ != nullptr; }
    visualization::rendering::RenderConfig& Config() { return config_; }
    const visualization::rendering::RenderConfig& Config() const { return config_; }
    int Width() const { return width_; }
    int Height() const { return height_; }
    std::string BackendName() const;
    const std::vector<std::string>& Names() const { return names_; }

    /// No material: a cloud's default way (splats for a Gaussian splat cloud).
    void AddCloud(const std::string& name, const t::geometry::PointCloud& cloud,
                  const std::optional<visualization::rendering::MaterialRecord>& material);
    void AddMesh(const std::string& name, const t::geometry::TriangleMesh& mesh,
                 const visualization::rendering::MaterialRecord& material);
    void UpdateCloud(const std::string& name, const t::geometry::PointCloud& cloud);
    bool Remove(const std::string& name);
    void Show(const std::string& name, bool show);
    bool Has(const std::string& name) const;
    void Clear();
    visualization::rendering::GaussianSplatRenderer& SplatRenderer() const;
    void SetBackground(const Eigen::Vector3d& rgb);

    /// Uses the camera. A camera of another size than the renderer's is refused unless
    /// `rescale`, which scales its intrinsics to the renderer's size (another aspect ratio
    /// stretches the picture: what used to happen unasked).
    void SetCamera(const camera::PinholeCamera& camera, bool rescale);
    const camera::PinholeCamera& Camera() const;

    /// The splat backend's frame of the current camera (renderers without meshes).
    visualization::rendering::RenderOutput Render(bool expected_depth, bool median_depth,
                                                  bool splat_id = false);
    /// The ID image (Int32 [H, W, 1], RenderOutput::splat_id) of the current camera: IDs of
    /// the merged scene, GaussianSplatRenderer::LocateSplat names their clouds. Renderers
    /// without meshes and without a stream only.
    t::geometry::Image RenderSplatId();
    /// Filament's frame: UInt8 [H, W, 3], or the view z Float32 [H, W, 1] with `depth`.
    t::geometry::Image RenderWithMeshes(bool depth);
    /// Renders into `destination` (N x H x W x 4 elements of float32, or uint8 with `uint8`),
    /// which lies in `memory` when that is set (the device then copies into it directly).
    /// Cameras of another size are refused unless `rescale` (as SetCamera).
    void RenderBatch(const std::vector<camera::PinholeCamera>& cameras, bool rescale, bool uint8,
                     uint8_t* destination,
                     const visualization::rendering::BatchHostMemory& memory = {});

private:
    /// Validated and at the renderer's size (see SetCamera); `what` names it in errors.
    camera::PinholeCamera Sized(const camera::PinholeCamera& camera, bool rescale,
                                const std::string& what) const;
    void RequireVisibleSplats() const;

    int width_, height_;
    std::unique_ptr<visualization::rendering::GaussianSplatRenderer> renderer_;
    std::unique_ptr<visualization::rendering::OffscreenRenderer> filament_;
    std::vector<std::string> names_;
    visualization::rendering::RenderConfig config_;
    camera::PinholeCamera camera_;
    bool has_camera_ = false;
};

/// Python's OffscreenRenderer.scene: a handle on the renderer's state, which it keeps alive.
struct SplatScene {
    std::shared_ptr<SplatOffscreen> renderer;
};

}  // namespace pybind
}  // namespace open3d
