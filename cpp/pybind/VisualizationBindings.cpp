// visualization.draw: the interactive viewer of the C++ library (needs an X server).
#include <pybind11/stl.h>

#include <fmt/format.h>

#include <string>
#include <vector>

#include "Bindings.h"
#include "PyPointCloud.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/visualizer/Visualizer.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

void BindVisualization(py::module_& m) {
    m.def(
        "draw",
        [](const py::list& geometries, const std::string& title, int width, int height,
           double max_seconds, uint64_t gpu_budget) {
            std::vector<visualization::DrawObject> objects;
            int index = 0;
            for (const py::handle& item : geometries) {
                visualization::DrawObject object;
                object.name = fmt::format("cloud_{}", index);
                py::handle geometry = item;
                if (py::isinstance<py::tuple>(item) && py::len(item) == 2) {
                    const py::tuple pair = item.cast<py::tuple>();
                    object.name = pair[0].cast<std::string>();
                    geometry = pair[1];
                }
                if (py::isinstance<PyPointCloud>(geometry)) {
                    object.geometry = geometry.cast<const PyPointCloud&>().cloud;
                } else if (py::isinstance<py::str>(geometry)) {
                    visualization::StreamedSplats stream;
                    stream.path = geometry.cast<std::string>();
                    stream.options.gpu_budget = gpu_budget;
                    object.geometry = stream;
                } else {
                    core::ThrowError(
                        "draw: item {} is neither a PointCloud, the path of a paged file "
                        "(.gspages) to stream, nor a (name, either) pair",
                        index);
                }
                objects.push_back(std::move(object));
                ++index;
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
        "Opens the viewer with the clouds (PointCloud or (name, PointCloud) items; a str item is "
        "the path of a paged file, .gspages, streamed into a GPU pool of gpu_budget bytes, 0: "
        "the default) and runs until the window closes (or max_seconds pass). Needs an X "
        "server: without one the error says to run under xvfb-run.");
}

}  // namespace pybind
}  // namespace open3d
