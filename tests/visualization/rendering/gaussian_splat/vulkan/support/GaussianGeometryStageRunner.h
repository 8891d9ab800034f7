// A small synchronous driver around GaussianGeometryStage for the tests
// (open3d_test_support_vulkan): it uploads a packed scene once, then per Run() records geometry
// stage, submits, waits on the fence and reads back the projected splats, the depth-ordered visible
// list, the sorted tile entries and the counters. Frames of the real backend submit without
// waiting.
#pragma once

#include <cstdint>
#include <vector>

#include "GaussianSplatTileListContract.h"
#include "open3d/camera/PinholeCamera.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatDataPacking.h"
#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Buffer.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStage.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianGeometryStageResources.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

/// What one geometry stage run produced, copied to the host after the fence.
struct GeometryStageReadback {
    shader::GaussianGeometryStageCounters counters{};
    int64_t num_splats = 0;
    /// [N] (empty unless asked for); only entries of visible splats were written this run (others
    /// hold stale data).
    std::vector<shader::GaussianProjectedSplat> projected;
    /// [visible_count]: splat indices, ascending float32 depth, ties by splat index
    /// (SortMode::kPackedKey32: the projection's append order, not sorted).
    std::vector<uint32_t> visible_in_depth_order;
    /// [entry_count]: tile index per entry, ascending.
    std::vector<uint32_t> entry_tiles;
    /// [entry_count]: splat index per entry; front to back within each tile (kPackedKey32:
    /// by truncated depth, ties in append order).
    std::vector<uint32_t> entry_splats;
    /// Wall-clock time from submit to fence of the geometry stage command buffer.
    double geometry_stage_ms = 0.0;

    RenderStats ToStats() const;
};

class GaussianGeometryStageRunner {
public:
    /// Uploads `packed` and allocates per-view buffers for up to `entry_capacity` tile
    /// entries. A degree-0 scene gets a 16-byte placeholder for the SH binding.
    GaussianGeometryStageRunner(const VulkanContext& context, const PackedGaussianSplats& packed,
                                uint32_t entry_capacity, GeometryStageOptions options = {});

    /// Replaces the visibility mask ([ceil(N / 32)] words, as in PackedGaussianSplats).
    void SetVisibility(const std::vector<uint32_t>& mask);

    /// Records, submits and waits for geometry stage of one view, then reads everything back.
    /// Each error flag is logged as a warning the first time this runner (one view) sees it.
    GeometryStageReadback Run(const camera::PinholeCamera& camera, const RenderConfig& config,
                              bool read_projected = true);

    /// Bytes of the scene buffers on the GPU (positions + shape + SH + mask).
    uint64_t GetSceneBytes() const { return resources_.SceneBytes(); }

private:
    const VulkanContext& context_;
    CommandPool pool_;
    GaussianGeometryStage geometry_stage_;
    GeometryStageResources resources_;
    uint32_t warned_flags_ = 0;
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
