// Open3D's OffscreenRenderer: an engine, a renderer and one Open3DScene of a fixed image
// size, for rendering without a window (an X server is still needed: Filament 1.9's OpenGL
// backend is GLX only; run under xvfb-run where there is no display).
//
//   OffscreenRenderer renderer(640, 480);
//   MaterialRecord splat;
//   splat.shader = "gaussianSplat";
//   renderer.GetScene()->AddGeometry("splats", cloud, splat);
//   renderer.SetupCamera(60.0f, center, eye, up);
//   t::geometry::Image rgb = renderer.RenderToImage();
#pragma once

#include <Eigen/Core>

#include <memory>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/Image.h"
#include "open3d/visualization/rendering/filament/Open3DScene.h"

namespace open3d {
namespace visualization {
namespace rendering {

class FilamentEngine;
class FilamentRenderer;

class OffscreenRenderer {
public:
    /// Starts its own Filament engine. Throws core::Open3DError when the size is not
    /// positive, no X server is reachable, or the named splat backend cannot be made.
    OffscreenRenderer(int width, int height, const Open3DSceneOptions& options = {});
    /// Renders with an existing engine (one engine per process is the cheap way to make
    /// many renderers); `engine` must outlive this.
    OffscreenRenderer(FilamentEngine& engine, int width, int height,
                      const Open3DSceneOptions& options = {});
    ~OffscreenRenderer();
    OffscreenRenderer(const OffscreenRenderer&) = delete;
    OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

    int GetWidth() const { return width_; }
    int GetHeight() const { return height_; }
    /// The scene rendered (Open3D returns a pointer here too).
    Open3DScene* GetScene() { return scene_.get(); }
    FilamentRenderer& GetRenderer() { return *renderer_; }

    /// Looks from `eye` at `center` with `up` up in the image and a vertical field of view
    /// in degrees.
    void SetupCamera(float vertical_fov_deg, const Eigen::Vector3f& center,
                     const Eigen::Vector3f& eye, const Eigen::Vector3f& up);
    /// A 3x3 pinhole intrinsic matrix and a 4x4 world-to-camera extrinsic (OpenCV axes),
    /// at the renderer's size.
    void SetupCamera(const Eigen::Matrix3d& intrinsic, const Eigen::Matrix4d& extrinsic);
    /// A full camera; resized to the renderer's size when it differs.
    void SetupCamera(const camera::PinholeCamera& camera);

    /// UInt8 [H, W, 3]: splats over meshes and points over the background.
    t::geometry::Image RenderToImage();
    /// Float32 [H, W, 1]: Filament's reversed-Z depth (near / z: 1 at the near plane, 0
    /// where nothing is), or with `z_in_view_space` the view z in scene units (0 where
    /// nothing is).
    t::geometry::Image RenderToDepthImage(bool z_in_view_space = false);

private:
    void Build(const Open3DSceneOptions& options);

    int width_ = 0, height_ = 0;
    std::unique_ptr<FilamentEngine> own_engine_;
    FilamentEngine* engine_ = nullptr;
    std::unique_ptr<FilamentRenderer> renderer_;
    std::unique_ptr<Open3DScene> scene_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
