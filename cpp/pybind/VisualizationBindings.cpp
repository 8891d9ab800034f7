// visualization.draw: the interactive viewer of the C++ library (needs an X server).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fmt/format.h>

#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "Bindings.h"
#include "PathArgs.h"
#include "PyMaterial.h"
#include "PyPointCloud.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/visualizer/Visualizer.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

namespace {

// One item of draw()'s list: a geometry, a (name, geometry) pair or Open3D's dict
// {"name", "geometry", "material", "is_visible"}. Paths are checked here, before the window
// opens, so that a missing file needs no display to be reported.
visualization::DrawObject DrawItem(const py::handle& item, int index, uint64_t gpu_budget) {
    visualization::DrawObject object;
    object.name = fmt::format("cloud_{}", index);
    py::handle geometry = item;
    std::optional<PyMaterialRecord> material;
    if (py::isinstance<py::tuple>(item) && py::len(item) == 2) {
        const py::tuple pair = item.cast<py::tuple>();
        object.name = py::str(pair[0]);
        geometry = pair[1];
    } else if (py::isinstance<py::dict>(item)) {
        const py::dict entry = item.cast<py::dict>();
        static const std::set<std::string> kKeys = {"name", "geometry", "material", "is_visible"};
        for (const auto& [key, value] : entry) {
            if (!kKeys.count(py::str(key))) {
                core::ThrowError(
                    "draw: item {}: unknown key '{}' (keys: name, geometry, material, "
                    "is_visible)",
                    index, std::string(py::str(key)));
            }
        }
        if (!entry.contains("geometry")) {
            core::ThrowError("draw: item {}: a dict item needs 'geometry'", index);
        }
        geometry = entry["geometry"];
        if (entry.contains("name")) object.name = py::str(entry["name"]);
        if (entry.contains("material") && !entry["material"].is_none()) {
            material = entry["material"].cast<PyMaterialRecord>();
        }
        if (entry.contains("is_visible")) object.visible = entry["is_visible"].cast<bool>();
    }
    const py::module_ os = py::module_::import("os");
    if (py::isinstance<PyPointCloud>(geometry)) {
        object.geometry = geometry.cast<const PyPointCloud&>().cloud;
        object.material = CloudMaterial(material);
    } else if (py::isinstance<t::geometry::TriangleMesh>(geometry)) {
        object.geometry = geometry.cast<const t::geometry::TriangleMesh&>();
        if (material) object.material = *material;
    } else if (py::isinstance<py::str>(geometry) || py::isinstance(geometry, os.attr("PathLike"))) {
        visualization::StreamedSplats stream;
        stream.path = InputPath(geometry.cast<std::filesystem::path>());
        stream.options.gpu_budget = gpu_budget;
        object.geometry = stream;
    } else {
        core::ThrowError(
            "draw: item {} is neither a PointCloud, a TriangleMesh, the path of a paged file "
            "(.gspages) to stream, a (name, geometry) pair nor a dict {{'name': ..., "
            "'geometry': ...}}",
            index);
    }
    return object;
}

}  // namespace

void BindVisualization(py::module_& m) {
    m.def(
        "draw",
        [](const py::object& geometries, const std::string& title, int width, int height,
           double max_seconds, uint64_t gpu_budget) {
            std::vector<visualization::DrawObject> objects;
            if (py::isinstance<py::list>(geometries)) {
                int index = 0;
                for (const py::handle& item : geometries) {
                    objects.push_back(DrawItem(item, index++, gpu_budget));
                }
            } else {  // draw(pcd), as Open3D takes one geometry alone too
                objects.push_back(DrawItem(geometries, 0, gpu_budget));
            }
            visualization::VisualizerOptions options;
            options.title = title;
            options.width = width;
            options.height = height;
            visualization::RunOptions run;
            run.max_seconds = max_seconds;
            py::gil_scoped_release release;
            visualization::Draw(objects, options, run);
        },
        py::arg("geometries"), py::arg("title") = "Open3D", py::arg("width") = 1280,
        py::arg("height") = 720, py::arg("max_seconds") = 0.0, py::arg("gpu_budget") = 0,
        "Opens the viewer with the items (a list, or one item alone) and runs until the window "
        "closes (or max_seconds "
        "pass). An item is a PointCloud, a TriangleMesh, a (name, geometry) pair, Open3D's "
        "dict {'name': ..., 'geometry': ..., 'material': MaterialRecord, 'is_visible': bool}, "
        "or the path (str or os.PathLike) of a paged file, .gspages, streamed into a GPU pool "
        "of gpu_budget bytes (0: the default). Needs an X server: without one the error says "
        "to run under xvfb-run.");
}

}  // namespace pybind
}  // namespace open3d
