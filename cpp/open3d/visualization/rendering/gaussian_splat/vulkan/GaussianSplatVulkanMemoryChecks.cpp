// The Vulkan backend's device-memory checks before work that would not fit: a view's images
// (before its geometry stage) and a level-of-detail hierarchy (before it is built).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "open3d/core/Exception.h"
#include "open3d/core/HostMemory.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStage.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianLodCut.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianSplatVulkanBackend.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

void GaussianSplatVulkanBackend::CheckViewFits(uint32_t width, uint32_t height) const {
    if (color_ && depth_ && width == width_ && height == height_) return;
    // Per pixel: the depth, alpha and median targets (4 bytes each), the RGBA32F colour
    // image and its readback (16 each), the depth and median readbacks (4 each), and the
    // composite's state. All are counted in the device-local heap: on a discrete GPU the
    // readbacks live in host memory, so this errs on the side of refusing.
    const uint64_t pixels = uint64_t(width) * height;
    const uint64_t need =
        pixels * (3 * 4 + 16 + 16 + 4 + 4) + GaussianCompositeStage::StateBytes(width, height);
    const DeviceMemoryBudget& budget = context_->GetMemoryBudget();
    const uint32_t heap =
        budget.HeapOf(context_->FindMemoryType(~0u, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT));
    // The images of the current size go when the new ones come.
    uint64_t held = composite_state_ ? composite_state_.GetSize() : 0;
    for (const Image* image : {&depth_, &alpha_, &median_, &color_}) {
        held += *image ? image->GetAllocationSize() : 0;
    }
    for (const Buffer* buffer : {&color_readback_, &depth_readback_, &median_readback_}) {
        held += *buffer ? buffer->GetSize() : 0;
    }
    const uint64_t available = budget.Available(heap) + held;
    if (need <= available) return;
    // The suggestion leaves a third of the room to the geometry stage's tile and entry
    // buffers, which grow with the image too (sqrt(2/3) of each side).
    const double scale = std::sqrt(double(available) / double(need) * 2.0 / 3.0);
    core::ThrowError(
        "Vulkan backend: a {}x{} view needs {} of device memory for its images, {} is free; "
        "{}x{} would fit (or render with the cpu backend)",
        width, height, core::FormatBytes(need), core::FormatBytes(available),
        std::max(1, int(width * scale)), std::max(1, int(height * scale)));
}

uint64_t GaussianSplatVulkanBackend::MinHierarchyDeviceBytes(int64_t num_leaves,
                                                             int sh_degree) const {
    // The least any hierarchy over these leaves takes: at most 8 children per inner node
    // (SplatHierarchy.cpp) gives at least (leaves - 1) / 7 inner nodes. Each node stores its
    // splat (exact packing and a visibility bit), its LOD record and a child index; a frame
    // runs its buffers over a slot per leaf (GeometryStageViewResources::Allocate) with the
    // cut's buffers over the nodes, and tile entries on top (counted as none here).
    const PackedGaussianSplats layout =
        PackedSplatLayout(std::clamp(sh_degree, 0, 3), SplatPrecision::kExact);
    const uint64_t leaves = uint64_t(std::max<int64_t>(num_leaves, 1));
    const uint64_t inner = std::max<uint64_t>((leaves - 1 + 6) / 7, 1);
    const auto bytes_for = [&](uint64_t n_leaves, uint64_t n_inner) {
        const uint64_t n_nodes = n_leaves + n_inner;
        const double stored = double(n_nodes) * (double(layout.BytesPerSplat()) + 1.0 / 8.0 +
                                                 sizeof(shader::GaussianLodNode) + 4.0);
        if (n_nodes > UINT32_MAX) return stored * 2.0;  // refused later by the index check
        const GeometryStageStorageRequirements view =
            GaussianGeometryStage::GetStorageRequirements(uint32_t(n_leaves), 0);
        const double frame =
            double(view.projected_bytes + view.depth_keys_bytes + view.splat_indices_bytes +
                   view.tile_counts_bytes + view.scan_bytes + view.sort.keys_alt_bytes +
                   view.sort.values_alt_bytes + view.sort.histogram_bytes) +
            double(GaussianLodCut::BucketsBytes(uint32_t(n_inner)) +
                   GaussianLodCut::VisibilityBytes(uint32_t(n_nodes)) +
                   GaussianLodCut::GroupCountsBytes(uint32_t(n_nodes)) +
                   GaussianLodCut::ListBytes(uint32_t(n_leaves)) +
                   GaussianLodCut::WalkBytes(uint32_t(n_inner)));
        return stored + frame;
    };
    return uint64_t(bytes_for(leaves, inner));
}

void GaussianSplatVulkanBackend::CheckHierarchyFits(int64_t num_leaves, int sh_degree) const {
    const uint64_t leaves = uint64_t(std::max<int64_t>(num_leaves, 1));
    const uint64_t nodes = leaves + std::max<uint64_t>((leaves - 1 + 6) / 7, 1);
    const double need = double(MinHierarchyDeviceBytes(num_leaves, sh_degree));
    const DeviceMemoryBudget& budget = context_->GetMemoryBudget();
    const uint32_t heap =
        budget.HeapOf(context_->FindMemoryType(~0u, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT));
    // The present scene's buffers go when the hierarchy's come.
    const double available =
        double(budget.Available(heap) + geometry_stage_resources_.SceneBytes());
    if (need <= available) return;
    const double per_leaf = need / double(leaves);
    core::ThrowError(
        "Vulkan backend: a level-of-detail hierarchy over {} splats of SH degree {} needs at "
        "least {} of device memory ({} nodes and a frame's buffers), {} is free; about {} "
        "splats fit (fewer splats, a lower SH degree, or a streamed .gspages scene: "
        "docs/streaming.md)",
        num_leaves, sh_degree, core::FormatBytes(uint64_t(need)), nodes,
        core::FormatBytes(uint64_t(available)), int64_t(available / per_leaf));
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
