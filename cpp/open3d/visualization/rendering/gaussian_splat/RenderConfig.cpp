#include "open3d/visualization/rendering/gaussian_splat/RenderConfig.h"

#include <cmath>

#include "open3d/core/Exception.h"

namespace open3d {
namespace visualization {
namespace rendering {

void RenderConfig::Validate() const {
    if (!(std::isfinite(near_plane) && near_plane > 0.0)) {
        core::ThrowError("RenderConfig: near_plane must be a positive finite distance, got {}",
                         near_plane);
    }
}

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
