#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

#include <cmath>

#include "open3d/core/Exception.h"

namespace open3d {
namespace visualization {
namespace rendering {

bool SameGeometryConfig(const RenderConfig& a, const RenderConfig& b) {
    return a.near_plane == b.near_plane && a.sh_degree == b.sh_degree &&
           a.antialias == b.antialias && a.max_tiles_per_splat == b.max_tiles_per_splat &&
           a.max_tile_entries_total == b.max_tile_entries_total && a.sort_mode == b.sort_mode &&
           a.depth_order == b.depth_order && a.compact_storage == b.compact_storage &&
           a.lod_budget == b.lod_budget && a.lod_cut_search == b.lod_cut_search &&
           a.lod_target_ms == b.lod_target_ms;
}

void RenderConfig::Validate() const {
    if (!(std::isfinite(near_plane) && near_plane > 0.0)) {
        core::ThrowError("RenderConfig: near_plane must be a positive finite distance, got {}",
                         near_plane);
    }
    if (!(std::isfinite(lod_target_ms) && lod_target_ms >= 0.0)) {
        core::ThrowError("RenderConfig: lod_target_ms must be a frame time >= 0 (0: off), got {}",
                         lod_target_ms);
    }
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
