// GPU time of the passes of a frame from timestamp queries: one query pool with a begin and
// an end timestamp per pass, reset in the frame's command buffer and read after its fence.
// The backend and the benchmark time project, sort, composite and merge with it (lavapipe
// and NVIDIA both support timestamps on the compute queue).
#pragma once

#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanHandle.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

class VulkanContext;

/// The passes the renderer times (indices into GpuTimestamps).
enum class TimedPass : uint32_t {
    kProject = 0,  ///< geometry stage up to the visible list
    kSort,         ///< geometry stage's sorts, scan and emit
    kComposite,
    kDepthMerge,
    // Parts of kSort, for profiling (GaussianGeometryStage::Record times them when given
    // timestamps).
    kDepthSort,   ///< the depth sort of the visible list
    kScanEmit,    ///< tile-count scan, capacity check and entry emission
    kTileSort,    ///< the stable sort of the entries by tile
    kLodCut,      ///< part of kProject: a hierarchy's cut (GaussianLodCut), before the projection
    kLodCutList,  ///< part of kLodCut: the cut's bits made a list (counts, offsets, list)
    kCount
};

class GpuTimestamps {
public:
    /// A pool for `num_passes` passes (2 queries each). When the queue family has no
    /// timestamps, every call records nothing and Read() gives negative values.
    GpuTimestamps(const VulkanContext& context,
                  uint32_t num_passes = static_cast<uint32_t>(TimedPass::kCount));

    bool IsSupported() const { return static_cast<bool>(pool_); }

    /// Resets every query; record once per command buffer before any Begin/End.
    void RecordReset(VkCommandBuffer cmd) const;
    /// Timestamp after all earlier commands completed (ALL_COMMANDS).
    void RecordBegin(VkCommandBuffer cmd, uint32_t pass) const;
    void RecordEnd(VkCommandBuffer cmd, uint32_t pass) const;
    void RecordBegin(VkCommandBuffer cmd, TimedPass pass) const {
        RecordBegin(cmd, static_cast<uint32_t>(pass));
    }
    void RecordEnd(VkCommandBuffer cmd, TimedPass pass) const {
        RecordEnd(cmd, static_cast<uint32_t>(pass));
    }

    /// Milliseconds per pass after the command buffer's fence; -1 for a pass whose two
    /// timestamps were not both written (or when unsupported).
    std::vector<double> ReadMilliseconds() const;

private:
    VkDevice device_ = VK_NULL_HANDLE;
    uint32_t num_passes_ = 0;
    double period_ns_ = 0.0;
    uint64_t valid_mask_ = 0;
    UniqueQueryPool pool_;
};

/// A pass's milliseconds from GpuTimestamps::ReadMilliseconds; 0 when it was not recorded.
inline double PassMs(const std::vector<double>& ms, TimedPass pass) {
    return std::max(0.0, ms[static_cast<uint32_t>(pass)]);
}

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
