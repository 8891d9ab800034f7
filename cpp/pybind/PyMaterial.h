// Python's MaterialRecord: Open3D's fields plus whether `shader` was ever set. Open3D's
// default shader is "defaultUnlit" (points for a point cloud), which a splat-only renderer
// cannot draw; a MaterialRecord() whose shader was left alone means "the geometry's own way"
// instead: a Gaussian splat cloud is drawn as splats, a mesh unlit.
#pragma once

#include <optional>

#include "open3d/visualization/rendering/filament/MaterialRecord.h"

namespace open3d {
namespace pybind {

struct PyMaterialRecord : visualization::rendering::MaterialRecord {
    bool shader_set = false;

    /// For a point cloud: none (the cloud's default) while the shader was never set.
    std::optional<visualization::rendering::MaterialRecord> ForCloud() const {
        if (!shader_set) return std::nullopt;
        return static_cast<const visualization::rendering::MaterialRecord&>(*this);
    }
};

/// A cloud's material from an optional Python one (see PyMaterialRecord).
inline std::optional<visualization::rendering::MaterialRecord> CloudMaterial(
    const std::optional<PyMaterialRecord>& material) {
    return material ? material->ForCloud() : std::nullopt;
}

}  // namespace pybind
}  // namespace open3d
