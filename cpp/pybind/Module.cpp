// PYBIND11_MODULE of `open3d_gs._core`: the submodules, the error type, and the Vulkan
// backend registered once so that OffscreenRenderer(backend="vulkan") finds it.
#include <pybind11/pybind11.h>

#include <exception>
#include <string>

#include "Bindings.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanBackendRegistry.h"

namespace py = pybind11;

PYBIND11_MODULE(_core, m) {
    m.doc() = "open3d_gs: Gaussian splat scenes from Python (docs/python.md)";
    // The C++ library's errors arrive as open3d_gs.Open3DError (a RuntimeError) with the
    // C++ message. A message can hold bytes that are not UTF-8 (quoted from a file, e.g. a
    // JSON parser's "last read"): pybind11's own translation decodes strictly and then gives
    // an empty message, so undecodable bytes become \xNN escapes here instead.
    static py::exception<open3d::core::Open3DError> open3d_error(m, "Open3DError",
                                                                 PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const open3d::core::Open3DError& e) {
            const std::string what = e.what();
            PyObject* message =
                PyUnicode_DecodeUTF8(what.data(), Py_ssize_t(what.size()), "backslashreplace");
            if (message == nullptr) {  // only on memory exhaustion
                PyErr_Clear();
                PyErr_SetString(open3d_error.ptr(), "(the error message could not be decoded)");
                return;
            }
            PyErr_SetObject(open3d_error.ptr(), message);
            Py_DECREF(message);
        }
    });
    open3d::visualization::rendering::vulkan::RegisterVulkanBackend();
    py::module_ t = m.def_submodule("t", "Tensor-based geometry and I/O");
    py::module_ t_geometry = t.def_submodule("geometry", "PointCloud");
    py::module_ t_io = t.def_submodule("io", "read_point_cloud, write_point_cloud");
    py::module_ camera = m.def_submodule("camera", "PinholeCamera, read_cameras_json");
    py::module_ visualization = m.def_submodule("visualization", "draw");
    py::module_ rendering =
        visualization.def_submodule("rendering", "OffscreenRenderer without a display");
    open3d::pybind::BindGeometry(t_geometry);
    open3d::pybind::BindMesh(t_geometry);
    open3d::pybind::BindMaterial(rendering);
    open3d::pybind::BindIo(t_io);
    open3d::pybind::BindCamera(camera);
    open3d::pybind::BindScene(rendering);
    open3d::pybind::BindRendering(rendering);
    open3d::pybind::BindVisualization(visualization);
}
