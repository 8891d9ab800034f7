// PYBIND11_MODULE of `open3d_gs._core`: the submodules, the error type, and the Vulkan
// backend registered once so that OffscreenRenderer(backend="vulkan") finds it.
#include <pybind11/eval.h>
#include <pybind11/pybind11.h>

#include <cerrno>
#include <exception>
#include <string>

#include "Bindings.h"
#include "PathArgs.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/vulkan/VulkanBackendRegistry.h"

namespace py = pybind11;

namespace {

// A message can hold bytes that are not UTF-8 (quoted from a file, e.g. a JSON parser's
// "last read", or a file name): pybind11's own translation decodes strictly and then gives
// an empty message, so undecodable bytes become \xNN escapes here instead.
py::object Decoded(const std::string& text) {
    PyObject* decoded =
        PyUnicode_DecodeUTF8(text.data(), Py_ssize_t(text.size()), "backslashreplace");
    if (decoded == nullptr) {  // only on memory exhaustion
        PyErr_Clear();
        return py::str("(the error message could not be decoded)");
    }
    return py::reinterpret_steal<py::object>(decoded);
}

}  // namespace

PYBIND11_MODULE(_core, m) {
    m.doc() = "open3d_gs: Gaussian splat scenes from Python (docs/python.md)";
    m.attr("__version__") = OPEN3D_GS_VERSION;  // the project's version (CMakeLists.txt)
    // The C++ library's errors arrive as open3d_gs.Open3DError (a RuntimeError) with the
    // C++ message; a missing input file as Open3DFileNotFoundError, which is Open3DError and
    // FileNotFoundError both, so that code written for either catches it.
    static py::exception<open3d::core::Open3DError> open3d_error(m, "Open3DError",
                                                                 PyExc_RuntimeError);
    open3d_error.attr("__doc__") =
        "An error of the C++ library (a bad file, argument or device), with its message";
    py::dict scope;
    scope["__name__"] = "open3d_gs";
    scope["Open3DError"] = open3d_error;
    py::exec(R"(
class Open3DFileNotFoundError(FileNotFoundError, Open3DError):
    """A missing input file: both Open3DError and FileNotFoundError (errno ENOENT, filename
    the path); str() is the library's message."""

    def __str__(self):
        return self.strerror if self.strerror is not None else super().__str__()
)",
             scope);
    // Kept for the translator, which runs after module init; never freed (the interpreter's
    // teardown order would make a static py::object's destructor unsafe).
    static PyObject* file_not_found = scope["Open3DFileNotFoundError"].ptr();
    Py_INCREF(file_not_found);
    m.attr("Open3DFileNotFoundError") = scope["Open3DFileNotFoundError"];
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const open3d::pybind::FileNotFound& e) {
            py::object message = Decoded(e.what());
            py::object error = py::reinterpret_borrow<py::object>(file_not_found)(
                ENOENT, message, Decoded(e.Path()));
            PyErr_SetObject(file_not_found, error.ptr());
        } catch (const open3d::core::Open3DError& e) {
            PyErr_SetObject(open3d_error.ptr(), Decoded(e.what()).ptr());
        }
    });
    open3d::visualization::rendering::vulkan::RegisterVulkanBackend();
    py::module_ t = m.def_submodule("t", "Tensor-based geometry and I/O");
    py::module_ t_geometry = t.def_submodule("geometry", "PointCloud");
    py::module_ t_io = t.def_submodule(
        "io", "read_point_cloud, write_point_cloud, write_splat_pages, read_image, write_image");
    py::module_ io = m.def_submodule(
        "io",
        "Open3D's o3d.io names: read_image, write_image, read_point_cloud, write_point_cloud; "
        "VideoWriter");
    py::module_ camera = m.def_submodule("camera", "PinholeCamera, read_cameras_json");
    py::module_ visualization = m.def_submodule("visualization", "draw");
    py::module_ rendering =
        visualization.def_submodule("rendering", "OffscreenRenderer without a display");
    open3d::pybind::BindBoundingBoxes(t_geometry);
    open3d::pybind::BindGeometry(t_geometry);
    open3d::pybind::BindMesh(t_geometry);
    open3d::pybind::BindMaterial(rendering);
    open3d::pybind::BindIo(t_io);
    open3d::pybind::BindImageIo(t_io);
    open3d::pybind::BindImageIo(io);
    open3d::pybind::BindVideo(io);
    // o3d.io.read_point_cloud is how Open3D code reads clouds: the same functions (they give
    // t.geometry.PointCloud, the one cloud class here).
    io.attr("read_point_cloud") = t_io.attr("read_point_cloud");
    io.attr("write_point_cloud") = t_io.attr("write_point_cloud");
    open3d::pybind::BindCamera(camera);
    open3d::pybind::BindScene(rendering);
    open3d::pybind::BindRendering(rendering);
    open3d::pybind::BindVisualization(visualization);
}
