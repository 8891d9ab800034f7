// The Python extension module `open3d_gs._core` (docs/python.md): one function per part of
// the library, each adding its classes and functions to a submodule that mirrors the C++
// namespace (t.geometry, t.io, camera, visualization.rendering, visualization).
#pragma once

#include <pybind11/pybind11.h>

#include "open3d/t/geometry/Image.h"

namespace open3d {
namespace pybind {

void BindBoundingBoxes(pybind11::module_& t_geometry);
void BindGeometry(pybind11::module_& t_geometry);
void BindMesh(pybind11::module_& t_geometry);
void BindMaterial(pybind11::module_& rendering);
void BindIo(pybind11::module_& t_io);
void BindImageIo(pybind11::module_& io);
void BindVideo(pybind11::module_& io);

/// A numpy image (H, W) or (H, W, C), C 1..4, as an Image of the array's dtype (float32, uint8
/// or uint16 after ArrayForTensor's conversions); errors name write_image.
t::geometry::Image ImageFromArray(const pybind11::object& value);
void BindCamera(pybind11::module_& camera);
void BindScene(pybind11::module_& rendering);
void BindRendering(pybind11::module_& rendering);
void BindVisualization(pybind11::module_& visualization);

}  // namespace pybind
}  // namespace open3d
