// The splat half of a scene (docs/DESIGN.md "Layers"): owns the chosen backend, the named
// Gaussian clouds merged into the one scene the backend holds, the visibility mask over
// that merged scene, and the state of every view drawn from it. The Filament layer keeps
// one per FilamentScene and drives its two stages from FilamentRenderer::BeginFrame (the
// geometry stage) and Draw (the composite stage).
//
// Adding, removing or replacing a cloud rebuilds the merged scene on the next Prepare();
// showing or hiding one patches the backend's mask only. A backend holds the sorted
// entries of one view at a time, so when several views share a renderer the composite of
// a view whose geometry stage was overwritten runs that geometry stage again first.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "open3d/camera/PinholeCamera.h"
#include "open3d/t/geometry/PointCloud.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatBackend.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"
#include "open3d/visualization/rendering/gaussian_splat/SplatStreamSession.h"

namespace open3d {
namespace visualization {
namespace rendering {

/// Makes the backend `name` names; "auto" = "vulkan" when registered and a device exists,
/// else "placeholder" (with a warning). Throws core::Open3DError for an unknown name.
std::unique_ptr<GaussianSplatBackend> ResolveGaussianSplatBackend(const std::string& name);

class GaussianSplatRenderer {
public:
    /// `backend`: "auto" = "vulkan" when it is registered and a device exists, else
    /// "placeholder" (draws nothing and says so once); or any registered name.
    /// Throws core::Open3DError when a named backend cannot be made.
    explicit GaussianSplatRenderer(const std::string& backend = "auto");
    /// Takes an existing backend (tests, custom backends).
    explicit GaussianSplatRenderer(std::unique_ptr<GaussianSplatBackend> backend);
    ~GaussianSplatRenderer();
    GaussianSplatRenderer(const GaussianSplatRenderer&) = delete;
    GaussianSplatRenderer& operator=(const GaussianSplatRenderer&) = delete;

    GaussianSplatBackend& GetBackend() const { return *backend_; }
    std::string GetBackendName() const { return backend_->GetName(); }

    /// Adds a Gaussian cloud. Throws core::Open3DError when the name is taken, the cloud
    /// lacks the Gaussian attributes or a stream runs (nothing changes then).
    void AddCloud(const std::string& name, const t::geometry::PointCloud& cloud);
    /// Replaces a cloud, keeping its visibility (its hierarchy goes: it was built for the old
    /// cloud). Throws when the name is unknown. Clear() also ends a stream.
    void UpdateCloud(const std::string& name, const t::geometry::PointCloud& cloud);
    bool RemoveCloud(const std::string& name);
    /// Throws when the name is unknown.
    void ShowCloud(const std::string& name, bool show);
    /// A level-of-detail hierarchy of cloud `name` (t/geometry/SplatHierarchy.h, built from
    /// it; nullptr drops it). While that cloud is the only one and shown, a backend that draws
    /// hierarchies (SetSceneHierarchy) gets its nodes as the scene, and RenderConfig::
    /// lod_budget / lod_target_ms choose each frame's cut (0 and 0: every leaf, the cloud
    /// exactly); otherwise the cloud is drawn as it is. Throws when the name is unknown or the
    /// hierarchy was not built from this cloud.
    void SetCloudHierarchy(const std::string& name,
                           std::shared_ptr<const t::geometry::SplatHierarchy> hierarchy);
    /// Whether the backend's scene is a cloud's hierarchy (after Prepare).
    bool DrawsHierarchy() const { return hierarchy_scene_; }
    bool HasCloud(const std::string& name) const { return clouds_.count(name) > 0; }
    /// The cloud held under `name`; throws core::Open3DError when the name is unknown.
    const t::geometry::PointCloud& GetCloud(const std::string& name) const;
    bool IsCloudVisible(const std::string& name) const;
    std::vector<std::string> GetCloudNames() const;
    /// Removes every cloud, ends a stream and frees the backend's scene and view buffers now.
    void Clear();

    /// Streams a paged splat file (.gspages, gs-convert --pages) instead of clouds
    /// (docs/streaming.md "In the renderer and the viewer"): the backend holds a pool of
    /// options.gpu_budget bytes; the geometry stages of one view (the first drawn since, until
    /// released) give the streaming worker that view, and every Prepare shows the pages read
    /// since. The pool is stored at options.compact_storage's precision, and the stream's
    /// frames draw at it whatever their RenderConfig says. A stream replaces an earlier one.
    /// Throws core::Open3DError while clouds are held
    /// or for a refused file or options (nothing changes then), or when the backend cannot
    /// hold the pool (only "vulkan" can; an earlier stream has ended then).
    void StreamSplats(const std::string& path, const SplatStreamOptions& options = {});
    /// Ends the stream and frees its pool; false when there was none.
    bool StopStreaming();
    bool IsStreaming() const { return stream_ != nullptr; }
    /// Hides or shows the stream's splats (a hidden stream draws nothing and is given no
    /// view). Throws core::Open3DError when no stream runs.
    void ShowStream(bool show);
    bool IsStreamVisible() const { return stream_ && stream_visible_; }
    /// Where the stream stands as of the last Prepare; empty when not streaming.
    std::optional<SplatStreamProgress> GetStreamProgress() const;
    /// A streaming step waits for the next Prepare: the next frame's picture differs.
    bool HasStreamNews() const;

    /// Some visible cloud has splats, or a shown stream runs: the stages must run.
    bool HasVisibleSplats() const;
    /// Bounds of the visible splat centres (of the streamed file's centres while a shown
    /// stream runs); false when there are none.
    bool GetBounds(Eigen::Vector3d& min_bound, Eigen::Vector3d& max_bound) const;

    /// Uploads the merged scene or the visibility mask when they changed.
    void Prepare();

    /// The cloud and the index in it of splat `id` of the merged scene (an ID image's value,
    /// RenderOutput::splat_id), as of the last Prepare; nullopt for -1 or an ID past the
    /// scene. Throws core::Open3DError while a stream runs (its IDs are pool slots) or when
    /// the clouds changed since the last Prepare.
    std::optional<std::pair<std::string, int64_t>> LocateSplat(int64_t id) const;

    /// Geometry stage of view `view_id` (any caller-chosen key): submitted, not waited for.
    void RenderGeometryStage(uint64_t view_id, const camera::PinholeCamera& camera,
                             const RenderConfig& config);
    /// Composite stage of `view_id`'s last geometry stage; runs that geometry stage again
    /// first when another view's replaced it in the backend. Throws when the view never
    /// ran a geometry stage.
    void RenderCompositeStage(uint64_t view_id, RenderOutput& output,
                              const CompositeInputs& inputs = {});
    /// Makes sure the backend holds `view_id`'s sorted entries (for callers that composite
    /// through the backend directly, e.g. into shared images).
    void EnsureGeometryStage(uint64_t view_id);
    /// Forgets a view's state.
    void ReleaseView(uint64_t view_id);

    struct Counters {
        int64_t merged_rebuilds = 0;        ///< merged scenes built and uploaded
        int64_t mask_updates = 0;           ///< visibility masks sent without a rebuild
        int64_t geometry_stages = 0;        ///< geometry stages asked of the backend
        int64_t geometry_stage_reruns = 0;  ///< of those, re-run because another view intervened
    };
    const Counters& GetCounters() const { return counters_; }

private:
    struct Cloud {
        t::geometry::PointCloud cloud;
        int64_t first = 0;  ///< index of its first splat in the merged scene
        bool visible = true;
        /// SetCloudHierarchy's, dropped when the cloud is replaced.
        std::shared_ptr<const t::geometry::SplatHierarchy> hierarchy;
    };
    struct ViewState {
        camera::PinholeCamera camera;
        RenderConfig config;
    };

    std::vector<uint32_t> VisibilityMask() const;

    std::unique_ptr<GaussianSplatBackend> backend_;
    std::map<std::string, Cloud> clouds_;
    std::map<uint64_t, ViewState> views_;
    std::unique_ptr<SplatStreamSession> stream_;
    std::optional<uint64_t> stream_view_;  // the view the stream follows
    bool stream_visible_ = true;
    bool has_current_view_ = false;
    uint64_t current_view_ = 0;     // whose sorted entries the backend holds
    bool merged_dirty_ = false;     // clouds added, removed or replaced
    bool mask_dirty_ = false;       // a cloud shown or hidden
    bool merged_uses_mask_ = true;  // false: the backend has no mask; hidden clouds left out
    bool hierarchy_scene_ = false;  // the backend's scene is a cloud's hierarchy
    Counters counters_;
};

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
