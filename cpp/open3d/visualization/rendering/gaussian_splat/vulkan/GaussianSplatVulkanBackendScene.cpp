// The Vulkan backend's scene: a cloud uploaded whole, a level-of-detail hierarchy's nodes, a
// pool of slots a streamer writes into, and which splats are shown.
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/core/Logging.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

void GaussianSplatVulkanBackend::SetScene(const t::geometry::PointCloud& cloud) {
    cloud.ValidateGaussianSplat();
    // The backend keeps a host copy (re-packed when the storage precision changes); the
    // upload itself packs through a staging buffer of at most a million splats.
    core::RequireHostMemory(
        static_cast<uint64_t>(cloud.NumBytes()),
        fmt::format("vulkan backend: a host copy of {} splats", cloud.NumPoints()), "fewer splats");
    WaitForStageWork();
    geometry_ = GeometryState{};
    cloud_ = cloud;
    pool_scene_ = false;
    visibility_mask_.clear();
    RetireLod();
    lod_controller_.Reset();
    UploadScene(SplatPrecision::kExact);
}

bool GaussianSplatVulkanBackend::SetSceneHierarchy(const t::geometry::PointCloud& source,
                                                   const t::geometry::SplatHierarchy& hierarchy) {
    source.ValidateGaussianSplat();
    // Every pass after the cut runs over its list, at most a slot per leaf; the cut's own
    // passes index nodes with 32-bit integers. Refused before the nodes are gathered.
    if (hierarchy.num_leaves > int64_t(SortMaxCount()) ||
        hierarchy.NumNodes() > int64_t(INT32_MAX)) {
        core::ThrowError(
            "Vulkan backend: a hierarchy of {} nodes ({} splats + {} inner) exceeds the {} "
            "splats the depth sort takes on this device or the {} nodes the cut indexes",
            hierarchy.NumNodes(), hierarchy.num_leaves, hierarchy.NumInner(), SortMaxCount(),
            INT32_MAX);
    }
    const PackedLodNodes lod = PackLodNodes(hierarchy);
    t::geometry::PointCloud nodes = HierarchyNodeCloud(hierarchy, source);
    WaitForStageWork();
    geometry_ = GeometryState{};
    cloud_ = std::move(nodes);
    pool_scene_ = false;
    visibility_mask_.clear();
    RetireLod();
    lod_controller_.Reset();
    UploadScene(SplatPrecision::kExact);
    geometry_stage_resources_.UploadLod(*context_, pool_, lod);
    return true;
}

void GaussianSplatVulkanBackend::SetScenePool(int64_t capacity, int sh_degree,
                                              const Eigen::Vector3d& center_min,
                                              const Eigen::Vector3d& center_max,
                                              bool compact_storage) {
    if (capacity < 1 || capacity > int64_t(UINT32_MAX)) {
        core::ThrowError("Vulkan backend: a scene pool of {} splats (1 to 2^32 - 1)", capacity);
    }
    if (sh_degree < 0 || sh_degree > 3) {
        core::ThrowError("Vulkan backend: a scene pool of SH degree {}", sh_degree);
    }
    // Allocated and zero-filled on the GPU: packing millions of placeholder splats on the
    // host took seconds before the first image.
    PackedGaussianSplats like = PackedSplatLayout(sh_degree, SplatPrecisionFor(compact_storage));
    like.center_min = center_min;
    like.center_max = center_max;
    WaitForStageWork();
    geometry_ = GeometryState{};
    RetireLod();
    lod_controller_.Reset();
    RetireSceneBuffers(false);
    ++scene_serial_;
    geometry_stage_resources_.AllocateScene(*context_, pool_, like, capacity);
    cloud_ = t::geometry::PointCloud();  // no host copy: the pages are on disk
    pool_scene_ = true;
    visibility_mask_.assign((capacity + 31) / 32, 0u);
    ++counters_.scene_uploads;
}

void GaussianSplatVulkanBackend::WriteSceneSplats(int64_t first,
                                                  const t::geometry::PointCloud& splats) {
    WriteSceneSplatRanges({{first, &splats}});
}

void GaussianSplatVulkanBackend::WriteSceneSplatRanges(
    const std::vector<std::pair<int64_t, const t::geometry::PointCloud*>>& ranges) {
    if (!cloud_) core::ThrowError("Vulkan backend: WriteSceneSplats before SetScene");
    if (geometry_stage_resources_.HasLod()) {
        core::ThrowError(
            "Vulkan backend: a scene drawn through its hierarchy takes no splat writes");
    }
    const int64_t scene_splats = geometry_stage_resources_.Layout().num_splats;
    const int degree = geometry_stage_resources_.Layout().sh_degree;
    // A plain scene keeps its host copy (re-packed when the storage precision changes) in
    // step; a pool has none.
    const bool host_copy = !pool_scene_;
    for (const auto& [first, cloud] : ranges) {
        const t::geometry::PointCloud& splats = *cloud;
        splats.ValidateGaussianSplat();
        const int64_t n = splats.NumPoints();
        if (first < 0 || first + n > scene_splats) {
            core::ThrowError("Vulkan backend: writing splats [{}, {}) into a scene of {}", first,
                             first + n, scene_splats);
        }
        if (splats.GetGaussianSplatArrays().sh_degree != degree) {
            core::ThrowError(
                "Vulkan backend: writing splats of SH degree {} into a scene of degree {}",
                splats.GetGaussianSplatArrays().sh_degree, degree);
        }
        if (!host_copy) continue;
        for (const std::string& name : cloud_->GetPointAttrNames()) {
            const core::Tensor& to = cloud_->GetPointAttr(name);
            const core::Tensor& from = splats.GetPointAttr(name);  // throws when absent
            if (from.NumBytes() != n * (to.NumBytes() / cloud_->NumPoints()) ||
                from.GetDtype() != to.GetDtype()) {
                core::ThrowError(
                    "Vulkan backend: the written splats' {} is not shaped like the scene's", name);
            }
        }
    }
    WaitForStageWork();
    geometry_.in_flight = false;
    WaitAllSlots();  // frames in flight read the buffers written here
    if (host_copy) {
        // In order: where ranges overlap, the later one's rows stay.
        for (const auto& [first, cloud] : ranges) {
            for (const std::string& name : cloud_->GetPointAttrNames()) {
                core::Tensor& to = cloud_->GetPointAttr(name);
                const core::Tensor& from = cloud->GetPointAttr(name);
                const int64_t row = to.NumBytes() / cloud_->NumPoints();
                std::memcpy(static_cast<uint8_t*>(to.RawData()) + first * row, from.RawData(),
                            cloud->NumPoints() * row);
            }
        }
    }
    geometry_stage_resources_.WriteSplats(*context_, pool_, ranges);
    geometry_.valid = false;  // the geometry stage's output is stale
}

int64_t GaussianSplatVulkanBackend::MaxSceneSplats() const {
    // The depth sort over a slot per splat (its keys and the other per-splat words within one
    // binding); the splats' own words are read by device address, and the per-splat passes
    // lay their workgroups out in rows past maxComputeWorkGroupCount[0] (DispatchGridFor).
    return static_cast<int64_t>(SortMaxCount());
}

void GaussianSplatVulkanBackend::ApplyStreamStep(const SplatStreamStep& step) {
    std::vector<std::pair<int64_t, const t::geometry::PointCloud*>> ranges;
    for (const SplatStreamStep::PageWrite& write : step.writes) {
        ranges.emplace_back(write.first_splat, &write.splats);
    }
    if (!ranges.empty()) WriteSceneSplatRanges(ranges);
    SetVisibility(step.visibility);
}

void GaussianSplatVulkanBackend::UploadScene(SplatPrecision precision) {
    RetireSceneBuffers(false);
    ++scene_serial_;
    // Packed a part at a time into a staging buffer (no packed copy of the scene on the host).
    geometry_stage_resources_.UploadSceneInParts(*context_, pool_, *cloud_, precision,
                                                 visibility_mask_);
    ++counters_.scene_uploads;
}

void GaussianSplatVulkanBackend::SetVisibility(const std::vector<uint32_t>& mask) {
    if (!cloud_) core::ThrowError("Vulkan backend: SetVisibility before SetScene");
    if (geometry_stage_resources_.HasLod()) {
        core::ThrowError(
            "Vulkan backend: a scene drawn through its hierarchy takes no visibility mask (the "
            "level-of-detail cut is its mask)");
    }
    WaitForStageWork();
    geometry_.in_flight = false;
    RetireSceneBuffers(true);
    ++scene_serial_;
    geometry_stage_resources_.UploadVisibility(*context_, pool_, mask);
    visibility_mask_ = mask;
    geometry_.valid = false;  // hidden splats change geometry stage's output
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
