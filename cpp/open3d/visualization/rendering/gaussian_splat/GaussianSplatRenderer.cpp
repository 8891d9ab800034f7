#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatRenderer.h"

#include <algorithm>

#include "open3d/core/Exception.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatMerge.h"

namespace open3d {
namespace visualization {
namespace rendering {

std::unique_ptr<GaussianSplatBackend> ResolveGaussianSplatBackend(const std::string& name) {
    if (name != "auto") return CreateGaussianSplatBackend(name);
    const std::vector<std::string> names = GetGaussianSplatBackendNames();
    if (std::find(names.begin(), names.end(), "vulkan") != names.end()) {
        try {
            return CreateGaussianSplatBackend("vulkan");
        } catch (const core::Open3DError& e) {
            core::LogWarning("No Vulkan device for Gaussian splats ({}); splats are not drawn",
                             e.what());
        }
    } else {
        core::LogWarning("No GPU splat backend is registered; splats are not drawn");
    }
    return CreateGaussianSplatBackend("placeholder");
}

namespace {

int64_t NumSplats(const t::geometry::PointCloud& cloud) {
    return cloud.GetPointPositions().GetShape(0);
}

}  // namespace

GaussianSplatRenderer::GaussianSplatRenderer(const std::string& backend)
    : backend_(ResolveGaussianSplatBackend(backend)) {}

GaussianSplatRenderer::GaussianSplatRenderer(std::unique_ptr<GaussianSplatBackend> backend)
    : backend_(std::move(backend)) {
    if (!backend_) core::ThrowError("GaussianSplatRenderer: no backend given");
}

GaussianSplatRenderer::~GaussianSplatRenderer() = default;

void GaussianSplatRenderer::AddCloud(const std::string& name,
                                     const t::geometry::PointCloud& cloud) {
    if (HasCloud(name)) core::ThrowError("GaussianSplatRenderer: a cloud named '{}' exists", name);
    if (stream_) {
        core::ThrowError(
            "GaussianSplatRenderer: cannot add cloud '{}' while '{}' streams (a stream is the "
            "whole splat scene; StopStreaming first)",
            name, stream_->File().GetFilename());
    }
    cloud.ValidateGaussianSplat();
    clouds_.emplace(name, Cloud{cloud, 0, true, nullptr});
    merged_dirty_ = true;
}

void GaussianSplatRenderer::UpdateCloud(const std::string& name,
                                        const t::geometry::PointCloud& cloud) {
    auto it = clouds_.find(name);
    if (it == clouds_.end()) core::ThrowError("GaussianSplatRenderer: no cloud named '{}'", name);
    cloud.ValidateGaussianSplat();
    it->second.cloud = cloud;
    it->second.hierarchy.reset();
    merged_dirty_ = true;
}

void GaussianSplatRenderer::SetCloudHierarchy(
    const std::string& name, std::shared_ptr<const t::geometry::SplatHierarchy> hierarchy) {
    auto it = clouds_.find(name);
    if (it == clouds_.end()) core::ThrowError("GaussianSplatRenderer: no cloud named '{}'", name);
    if (hierarchy) {
        const std::string mismatch =
            t::geometry::HierarchySourceMismatch(*hierarchy, it->second.cloud);
        if (!mismatch.empty()) {
            core::ThrowError("GaussianSplatRenderer: the hierarchy is not of cloud '{}': {}", name,
                             mismatch);
        }
    }
    it->second.hierarchy = std::move(hierarchy);
    merged_dirty_ = true;
}

bool GaussianSplatRenderer::RemoveCloud(const std::string& name) {
    if (clouds_.erase(name) == 0) return false;
    merged_dirty_ = true;
    return true;
}

void GaussianSplatRenderer::ShowCloud(const std::string& name, bool show) {
    auto it = clouds_.find(name);
    if (it == clouds_.end()) core::ThrowError("GaussianSplatRenderer: no cloud named '{}'", name);
    if (it->second.visible == show) return;
    it->second.visible = show;
    // Without a mask in the backend, hidden clouds are left out of the merged scene; a
    // hierarchy's nodes have no mask of the cloud's splats, so a scene that is or becomes a
    // hierarchy is made again.
    if (merged_uses_mask_ && !hierarchy_scene_ && !it->second.hierarchy) {
        mask_dirty_ = true;
    } else {
        merged_dirty_ = true;
    }
}

bool GaussianSplatRenderer::IsCloudVisible(const std::string& name) const {
    auto it = clouds_.find(name);
    if (it == clouds_.end()) core::ThrowError("GaussianSplatRenderer: no cloud named '{}'", name);
    return it->second.visible;
}

std::vector<std::string> GaussianSplatRenderer::GetCloudNames() const {
    std::vector<std::string> names;
    for (const auto& [name, cloud] : clouds_) names.push_back(name);
    return names;
}

void GaussianSplatRenderer::Clear() {
    StopStreaming();
    if (!clouds_.empty()) merged_dirty_ = true;
    clouds_.clear();
    // The backend's copy of the scene (host and device memory) goes now, not at the next
    // Prepare: a renderer kept for later scenes (open3d_gs.rasterization's cache) must not
    // hold the last one between calls.
    backend_->ReleaseResources();
    hierarchy_scene_ = false;
    has_current_view_ = false;
}

void GaussianSplatRenderer::StreamSplats(const std::string& path,
                                         const SplatStreamOptions& options) {
    if (!clouds_.empty()) {
        core::ThrowError(
            "GaussianSplatRenderer: cannot stream '{}' beside {} cloud(s) (a stream is the whole "
            "splat scene; remove them first)",
            path, clouds_.size());
    }
    // A refused file or budget leaves an earlier stream running; past this point it ends.
    auto stream = std::make_unique<SplatStreamSession>(path, options, backend_->MaxSceneSplats());
    StopStreaming();
    const t::io::SplatPageFile& file = stream->File();
    try {
        backend_->SetScenePool(stream->PoolSplats(), file.ShDegree(), file.CenterMin(),
                               file.CenterMax(), stream->CompactStorage());
    } catch (...) {
        backend_->ReleaseResources();  // a pool half made (device memory) is no scene
        throw;
    }
    stream_ = std::move(stream);
    stream_view_.reset();
    stream_visible_ = true;
    merged_dirty_ = mask_dirty_ = hierarchy_scene_ = false;
    has_current_view_ = false;
}

bool GaussianSplatRenderer::StopStreaming() {
    if (!stream_) return false;
    stream_.reset();
    stream_view_.reset();
    backend_->ReleaseResources();
    has_current_view_ = false;
    return true;
}

void GaussianSplatRenderer::ShowStream(bool show) {
    if (!stream_) core::ThrowError("GaussianSplatRenderer: no stream to show or hide");
    stream_visible_ = show;
}

std::optional<SplatStreamProgress> GaussianSplatRenderer::GetStreamProgress() const {
    if (!stream_) return std::nullopt;
    return stream_->Progress();
}

bool GaussianSplatRenderer::HasStreamNews() const { return stream_ && stream_->HasNews(); }

bool GaussianSplatRenderer::HasVisibleSplats() const {
    if (stream_) return stream_visible_;
    for (const auto& [name, cloud] : clouds_) {
        if (cloud.visible && NumSplats(cloud.cloud) > 0) return true;
    }
    return false;
}

bool GaussianSplatRenderer::GetBounds(Eigen::Vector3d& min_bound,
                                      Eigen::Vector3d& max_bound) const {
    if (stream_) {
        if (!stream_visible_) return false;
        min_bound = stream_->File().CenterMin();
        max_bound = stream_->File().CenterMax();
        return true;
    }
    bool any = false;
    for (const auto& [name, cloud] : clouds_) {
        const core::Tensor& p = cloud.cloud.GetPointPositions();
        if (!cloud.visible || p.GetShape(0) == 0) continue;
        const Eigen::Map<const Eigen::Matrix<float, 3, Eigen::Dynamic>> points(p.Data<float>(), 3,
                                                                               p.GetShape(0));
        const Eigen::Vector3d lo = points.rowwise().minCoeff().cast<double>();
        const Eigen::Vector3d hi = points.rowwise().maxCoeff().cast<double>();
        min_bound = any ? min_bound.cwiseMin(lo) : lo;
        max_bound = any ? max_bound.cwiseMax(hi) : hi;
        any = true;
    }
    return any;
}

std::vector<uint32_t> GaussianSplatRenderer::VisibilityMask() const {
    int64_t n = 0;
    for (const auto& [name, cloud] : clouds_) n += NumSplats(cloud.cloud);
    std::vector<uint32_t> mask((n + 31) / 32, 0u);
    for (const auto& [name, cloud] : clouds_) {
        if (!cloud.visible) continue;
        SetSplatVisibility(mask, cloud.first, cloud.first + NumSplats(cloud.cloud), true);
    }
    return mask;
}

const t::geometry::PointCloud& GaussianSplatRenderer::GetCloud(const std::string& name) const {
    const auto it = clouds_.find(name);
    if (it == clouds_.end()) core::ThrowError("GaussianSplatRenderer: no cloud named '{}'", name);
    return it->second.cloud;
}

std::optional<std::pair<std::string, int64_t>> GaussianSplatRenderer::LocateSplat(
    int64_t id) const {
    if (stream_) {
        core::ThrowError(
            "GaussianSplatRenderer: a streamed scene's IDs are pool slots, not splats");
    }
    if (merged_dirty_) {
        core::ThrowError(
            "GaussianSplatRenderer: the clouds changed since the last frame; render again to "
            "get IDs of the scene as it is");
    }
    if (id < 0) return std::nullopt;
    for (const auto& [name, cloud] : clouds_) {
        // Hidden clouds are left out of the merged scene unless the mask hides them.
        if (!merged_uses_mask_ && !cloud.visible) continue;
        if (id >= cloud.first && id < cloud.first + NumSplats(cloud.cloud)) {
            return std::pair{name, id - cloud.first};
        }
    }
    return std::nullopt;
}

void GaussianSplatRenderer::Prepare() {
    if (stream_) {
        if (std::optional<SplatStreamStep> step = stream_->Take()) {
            backend_->ApplyStreamStep(*step);
            has_current_view_ = false;  // the backend's sorted entries are of the old cut
        }
        return;
    }
    if (merged_dirty_) {
        std::vector<const t::geometry::PointCloud*> parts;
        int64_t first = 0;
        for (auto& [name, cloud] : clouds_) {
            cloud.first = first;
            if (!merged_uses_mask_ && !cloud.visible) continue;
            parts.push_back(&cloud.cloud);
            first += NumSplats(cloud.cloud);
        }
        hierarchy_scene_ = false;
        if (parts.empty()) {
            backend_->ReleaseResources();
        } else {
            // One cloud goes as it is: merging copies every splat first (1.4 s for 2M splats
            // on the 2-core machine, before the upload, with the window frozen). The only
            // cloud, shown, with a hierarchy goes as its nodes where the backend draws them.
            const Cloud* only = clouds_.size() == 1 ? &clouds_.begin()->second : nullptr;
            hierarchy_scene_ = only != nullptr && only->visible && only->hierarchy &&
                               backend_->SetSceneHierarchy(only->cloud, *only->hierarchy);
            if (!hierarchy_scene_) {
                if (parts.size() == 1) {
                    backend_->SetScene(*parts.front());
                } else {
                    backend_->SetScene(MergeGaussianSplatClouds(parts));
                }
            }
            ++counters_.merged_rebuilds;
            // A new scene starts all visible: send a mask only when something is hidden.
            mask_dirty_ = false;
            for (const auto& [name, cloud] : clouds_) mask_dirty_ |= !cloud.visible;
            mask_dirty_ &= merged_uses_mask_;
        }
        merged_dirty_ = false;
        has_current_view_ = false;  // the backend's sorted entries are of the old scene
    }
    if (mask_dirty_) {
        mask_dirty_ = false;
        has_current_view_ = false;
        if (backend_->SetVisibilityMask(VisibilityMask())) {
            ++counters_.mask_updates;
        } else {
            // The backend has no mask: from now on hidden clouds are left out instead.
            merged_uses_mask_ = false;
            merged_dirty_ = true;
            Prepare();
        }
    }
}

void GaussianSplatRenderer::RenderGeometryStage(uint64_t view_id,
                                                const camera::PinholeCamera& camera,
                                                const RenderConfig& config) {
    views_[view_id] = ViewState{camera, config};
    // The stream follows one view (the first drawn since it started, until released): views
    // taking turns would cut from the root every step and never let the worker rest.
    if (stream_) {
        if (!stream_view_) stream_view_ = view_id;
        if (*stream_view_ == view_id) stream_->SetView(camera);
    }
    // A stream's pool keeps the precision it was started with (no host copy to re-pack).
    RenderConfig frame = config;
    if (stream_) frame.compact_storage = stream_->CompactStorage();
    backend_->RenderGeometryStage(camera, frame);
    ++counters_.geometry_stages;
    current_view_ = view_id;
    has_current_view_ = true;
}

void GaussianSplatRenderer::EnsureGeometryStage(uint64_t view_id) {
    if (has_current_view_ && current_view_ == view_id) return;
    auto it = views_.find(view_id);
    if (it == views_.end()) {
        core::ThrowError("GaussianSplatRenderer: view {} has no geometry stage to composite",
                         view_id);
    }
    const ViewState state = it->second;
    RenderGeometryStage(view_id, state.camera, state.config);
    ++counters_.geometry_stage_reruns;
}

void GaussianSplatRenderer::RenderCompositeStage(uint64_t view_id, RenderOutput& output,
                                                 const CompositeInputs& inputs) {
    EnsureGeometryStage(view_id);
    backend_->RenderCompositeStage(output, inputs);
}

void GaussianSplatRenderer::ReleaseView(uint64_t view_id) {
    views_.erase(view_id);
    if (stream_view_ == view_id) stream_view_.reset();
    if (has_current_view_ && current_view_ == view_id) has_current_view_ = false;
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
