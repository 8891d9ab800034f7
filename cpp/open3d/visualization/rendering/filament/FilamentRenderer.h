// The seed's frame in three calls (docs/filament.md "Frame"):
//   BeginFrame: flushAndWait (the previous frame's GL work on the shared images is done),
//               then the splat geometry stage of every added view with splats is submitted
//               without a CPU wait, so it overlaps Filament's draw;
//   Draw(view): Filament draws the view's meshes and points (colour + the shared depth),
//               flushAndWait, then the composite stage tests the splats against that depth
//               and writes the shared RGBA16F (and the offscreen readbacks);
//   EndFrame:   on a swap chain, each drawn view's compose view (mesh colour blit + splat
//               overlay) and the overlay views (ImGui) are drawn and presented. They wait
//               until here because Filament allows no standalone render (the mesh views)
//               between its beginFrame and endFrame.
#pragma once

#include <functional>
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

/// What Draw produces for one view. The splat settings are the view's
/// (FilamentView::GetSplatConfig).
struct FrameRequest {
    /// Read the composed colour back (FrameResult::color).
    bool read_color = false;
    /// Read the swap chain's pixels after the compose view (EndFrame's return value, or
    /// FrameResult::screen of the one-call Draw); needs a swap chain made with
    /// CONFIG_READABLE.
    bool read_screen = false;
    /// Views drawn on the swap chain after the compose view, in order (e.g. an ImGui
    /// overlay); read_screen includes them. Ignored without a swap chain.
    std::vector<filament::View*> overlay_views;
    /// Merge and read the depth back (FrameResult::linear_depth / normalized_depth).
    bool read_depth = false;
    float depth_near = 0.01f;  ///< normalisation of normalized_depth
    float depth_far = 1000.0f;
    /// Asked once the meshes are drawn and while the splat geometry stage is waited for
    /// (then in slices of core::kWaitCallbackPeriodMs with the thread's wait callback
    /// between): true skips the rest of the view's frame (the composite, the readbacks, the
    /// compose view) and sets FrameResult::cancelled. The viewer's Q during a frame of
    /// seconds on a software device.
    std::function<bool()> cancelled;
    /// Draw the meshes and overlays only: no composite, the splats do not show. A geometry
    /// stage BeginFrame submitted keeps running (the viewer presents such a frame with a
    /// progress line while the first geometry stage of a large scene runs).
    bool skip_splats = false;
};

/// The steps of a frame, in the order the seed's design fixes (reported to a listener).
enum class FrameEvent {
    kBeginFrame,     ///< a frame begun (the previous frame's GL work may still run)
    kGeometryStage,  ///< a view's splat geometry stage submitted
    kFilamentDraw,   ///< a view's meshes and points drawn, depth ready
    kComposite,      ///< a view's splats composited against that depth
    kOverlay,        ///< a view's compose view (and overlay views) drawn on the swap chain
    kEndFrame        ///< presented
};
/// Called with each step and the view it concerns (null for kBeginFrame / kEndFrame).
using FrameEventListener = std::function<void(FrameEvent, const FilamentView*)>;

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
    bool cancelled = false;         ///< FrameRequest::cancelled said so: nothing was presented
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

    /// Views BeginFrame runs the geometry stage for; `scene` must outlive the entry.
    void AddView(FilamentScene& scene, FilamentView& view);
    void RemoveView(const FilamentView& view);

    /// Starts a frame that Draw calls fill and EndFrame presents on `swap_chain` (none:
    /// offscreen). Submits the geometry stage of every added view that has visible splats.
    /// Throws core::Open3DError when a frame is already begun.
    void BeginFrame(filament::SwapChain* swap_chain = nullptr);
    /// Draws one added view: meshes and points, then the splat composite; reads back what
    /// `request` asks for. A view whose geometry stage BeginFrame did not run gets it here.
    FrameResult Draw(FilamentView& view, const FrameRequest& request);
    /// Draws the drawn views' compose views and overlays on the swap chain and presents.
    /// Returns the screen pixels when a Draw asked for read_screen (else an empty image).
    t::geometry::Image EndFrame();
    bool IsFrameBegun() const { return frame_begun_; }

    /// One frame of one view in one call (BeginFrame, Draw, EndFrame), added or not; only
    /// this view's geometry stage runs. FrameResult::screen holds the screen pixels when
    /// asked for.
    FrameResult Draw(FilamentScene& scene, FilamentView& view, const FrameRequest& request,
                     filament::SwapChain* swap_chain = nullptr);

    /// Reports each step of every frame (tests of the frame order); empty to stop.
    void SetFrameEventListener(FrameEventListener listener) { listener_ = std::move(listener); }

private:
    struct ViewEntry {
        FilamentScene* scene = nullptr;
        FilamentView* view = nullptr;
        bool geometry_submitted = false;  // this frame
        double geometry_stage_ms = 0.0;
        FrameRequest request;  // of this frame's Draw (overlays, read_screen)
    };
    void StartFrame(filament::SwapChain* swap_chain);
    void SubmitGeometryStage(ViewEntry& entry);
    ViewEntry* FindView(const FilamentView& view);
    void Report(FrameEvent event, const FilamentView* view) const {
        if (listener_) listener_(event, view);
    }

    FilamentEngine& engine_;
    std::unique_ptr<FilamentMaterials> materials_;
    filament::Renderer* renderer_ = nullptr;
    std::vector<ViewEntry> views_;
    ViewEntry temporary_;  // the one-call Draw's view when it was not added
    bool frame_begun_ = false;
    filament::SwapChain* swap_chain_ = nullptr;
    std::vector<ViewEntry*> drawn_;  // this frame, in Draw order
    FrameEventListener listener_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
