// A small synchronous driver around GaussianCompositeStage for tests and tools: it uploads host
// arrays (projected splats, tile-sorted entries, an optional reversed-Z scene depth), records
// the composite (and optionally the depth merge) with GPU timestamps, submits, waits on the
// fence and reads every image back. Composite stage can so be tested without geometry stage. Frames
// of the real backend record into their own command buffers and do not wait.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "GaussianSplatCompositeContract.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/Commands.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GaussianCompositeStage.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/GpuTimestamps.h"

namespace open3d {
namespace visualization {
namespace rendering {
namespace vulkan {

struct CompositeStageRunInputs {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<shader::GaussianProjectedSplat> projected;  // [N]
    std::vector<uint32_t> entry_tiles;                      // [E] tile index, ascending
    std::vector<uint32_t> entry_splats;  // [E] splat index, front to back per tile
    std::array<float, 3> background{0.f, 0.f, 0.f};
    CompositeColorFormat color_format = CompositeColorFormat::kRgba32f;
    /// [H, W] reversed-Z values d = near / z_view (0 = nothing), row 0 on top, uploaded as a
    /// D32_SFLOAT texture; empty for none.
    std::vector<float> scene_depth;
    float scene_near = 0.1f;
    /// Store the texture bottom row first and let the shader flip (as with GL / Filament).
    bool scene_depth_flip_y = false;
    /// Upload and bind the scene depth but run the variants specialised without it: they
    /// must ignore it.
    bool scene_depth_unused = false;
    /// Also run the depth merge (of the expected depth and alpha).
    bool depth_merge = false;
    DepthMergeParams merge;  // its scene_depth is set by the runner
    uint32_t max_workgroups = 0;
};

/// What one run produced, row-major, row 0 on top.
struct CompositeStageReadback {
    std::vector<float> color;                 // [H, W, 4] (RGBA16F read back as float)
    std::vector<float> depth;                 // [H, W]
    std::vector<float> alpha;                 // [H, W]
    std::vector<float> median_depth;          // [H, W]
    std::vector<uint16_t> merged_normalized;  // [H, W] when depth_merge
    std::vector<float> merged_linear;         // [H, W] when depth_merge
    double composite_ms = -1.0;               ///< GPU timestamps; -1 when unsupported
    double merge_ms = -1.0;
    double wall_ms = 0.0;  ///< submit to fence
};

class GaussianCompositeStageRunner {
public:
    explicit GaussianCompositeStageRunner(const VulkanContext& context);

    /// Allocates, uploads, records, submits, waits and reads back. Throws on bad input.
    CompositeStageReadback Run(const CompositeStageRunInputs& inputs);

private:
    const VulkanContext& context_;
    CommandPool pool_;
    GaussianCompositeStage composite_stage_;
    GpuTimestamps timestamps_;
};

}  // namespace vulkan
}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
