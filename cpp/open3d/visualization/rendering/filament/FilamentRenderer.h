// The frame schedule (docs/filament.md "Frame"):
//   flushAndWait -> geometry stage submit (no CPU wait) -> Filament draws the meshes (colour +
//   the shared depth) -> flushAndWait -> composite stage (waits for the geometry stage's fence,
//   tests splats against the depth, writes the shared RGBA16F) -> the compose view blits the mesh
//   colour and blends the splat colour over it on a swap chain, and/or the offscreen readback
//   blends the two on the host.
#pragma once

#include <memory>
#include <vector>

#include "open3d/t/geometry/Image.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

namespace filament {
class Renderer;
class SwapChain;
class View;
}  // namespace filament

namespace open3d {
namespace visualization {
namespace rendering {

class FilamentEngine;
class FilamentMaterials;
class FilamentScene;
class FilamentView;

struct FrameRequest {
    /// Splat settings; `background` is ignored (the view's background shows through).
    RenderConfig splat_config;
    /// Read the composed colour back (FrameResult::color).
    bool read_color = false;
    /// Read the swap chain's pixels after the compose view (FrameResult::screen); needs a
    /// swap chain made with CONFIG_READABLE.
    bool read_screen = false;
    /// Views drawn on the swap chain after the compose view, in order (e.g. an ImGui
    /// overlay); read_screen includes them. Ignored without a swap chain.
    std::vector<filament::View*> overlay_views;
    /// Merge and read the depth back (FrameResult::linear_depth / normalized_depth).
    bool read_depth = false;
    float depth_near = 0.2f;  ///< normalisation of normalized_depth
    float depth_far = 100.0f;
};

/// Wall-clock parts of a frame in milliseconds (CPU side, including waits).
struct FrameTimes {
    double geometry_stage_ms = 0.0;  ///< geometry stage record + submit (and scene/mask uploads)
    double filament_ms = 0.0;        ///< mesh view render + flushAndWait
    double composite_stage_ms =
        0.0;  ///< the geometry stage fence wait + composite stage (+ GPU depth merge, readback)
    double compose_ms = 0.0;   ///< swap chain frame (blit + overlay), when drawn
    double readback_ms = 0.0;  ///< mesh colour readPixels + host blend (offscreen)
    double total_ms = 0.0;
};

struct FrameResult {
    /// UInt8 [H, W, 4], top row first: splat colour blended "over" the mesh view's colour.
    t::geometry::Image color;
    /// UInt8 [H, W, 4], top row first: what the compose view drew (read_screen).
    t::geometry::Image screen;
    /// Float32 [H, W, 1] nearer of splat and mesh view z, 0 where nothing is.
    t::geometry::Image linear_depth;
    /// UInt16 [H, W, 1] normalised, 65535 where nothing is.
    t::geometry::Image normalized_depth;
    RenderStats splat_stats;
    bool splats_drawn =
        false;  ///< some splat cloud was visible (geometry and composite stages ran)
    bool scene_depth_used = false;  ///< a mesh was visible, so splats were depth-tested
    FrameTimes times;
};

class FilamentRenderer {
public:
    explicit FilamentRenderer(FilamentEngine& engine);
    ~FilamentRenderer();
    FilamentRenderer(const FilamentRenderer&) = delete;
    FilamentRenderer& operator=(const FilamentRenderer&) = delete;

    FilamentEngine& GetEngine() const { return engine_; }
    const FilamentMaterials& GetMaterials() const { return *materials_; }
    filament::Renderer* GetFilamentRenderer() const { return renderer_; }

    /// One frame of `scene` through `view`. Draws to `swap_chain` when given (the caller
    /// presents it); reads back what `request` asks for. The splat pipeline always runs
    /// for visible splats (geometry stage is reused by the backend when nothing changed).
    FrameResult Draw(FilamentScene& scene, FilamentView& view, const FrameRequest& request,
                     filament::SwapChain* swap_chain = nullptr);

private:
    FilamentEngine& engine_;
    std::unique_ptr<FilamentMaterials> materials_;
    filament::Renderer* renderer_ = nullptr;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
