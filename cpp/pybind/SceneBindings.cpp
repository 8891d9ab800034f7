// visualization.rendering.Scene: the geometry of an OffscreenRenderer by name, and the
// paged files it streams.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <optional>
#include <string>

#include "Bindings.h"
#include "PathArgs.h"
#include "PyMaterial.h"
#include "PyPointCloud.h"
#include "SplatOffscreen.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/MaterialRecord.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatRenderer.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

void BindScene(py::module_& m) {
    using visualization::rendering::MaterialRecord;
    py::class_<SplatScene>(m, "Scene",
                           "The geometry of an OffscreenRenderer, by name: Gaussian splat "
                           "clouds, and with meshes=True meshes and point clouds too")
        .def(
            "add_geometry",
            [](SplatScene& s, const std::string& name, const PyPointCloud& cloud,
               const std::optional<PyMaterialRecord>& material) {
                s.renderer->AddCloud(name, cloud.cloud, CloudMaterial(material));
            },
            py::arg("name"), py::arg("geometry"), py::arg("material") = py::none(),
            "Adds a copy of a cloud (a Gaussian splat cloud unless the material says otherwise); "
            "raises for a taken name or a cloud without the Gaussian attributes")
        .def(
            "add_geometry",
            [](SplatScene& s, const std::string& name, const t::geometry::TriangleMesh& mesh,
               const std::optional<PyMaterialRecord>& material) {
                s.renderer->AddMesh(name, mesh,
                                    material ? MaterialRecord(*material) : MaterialRecord{});
            },
            py::arg("name"), py::arg("geometry"), py::arg("material") = py::none(),
            "Adds a copy of a mesh (renderers made with meshes=True)")
        .def(
            "update_geometry",
            [](SplatScene& s, const std::string& name, const PyPointCloud& cloud) {
                s.renderer->UpdateCloud(name, cloud.cloud);
            },
            py::arg("name"), py::arg("geometry"),
            "Replaces the cloud of that name by a copy of this one")
        .def(
            "remove_geometry",
            [](SplatScene& s, const std::string& name) { return s.renderer->Remove(name); },
            py::arg("name"), "Removes the geometry; False when there was none of that name")
        .def(
            "show_geometry",
            [](SplatScene& s, const std::string& name, bool show) { s.renderer->Show(name, show); },
            py::arg("name"), py::arg("show"), "Shows or hides the geometry (kept in the scene)")
        .def(
            "has_geometry",
            [](const SplatScene& s, const std::string& name) { return s.renderer->Has(name); },
            py::arg("name"), "Whether a geometry of that name is in the scene")
        .def(
            "clear_geometry", [](SplatScene& s) { s.renderer->Clear(); },
            "Removes every geometry and ends a stream")
        .def(
            "stream_splats",
            [](SplatScene& s, const std::filesystem::path& path, const py::object& gpu_budget,
               int64_t splat_budget, int64_t reads_per_step, std::optional<bool> compact_storage) {
                visualization::rendering::SplatStreamOptions options;
                if (py::isinstance<py::str>(gpu_budget)) {
                    options.gpu_budget =
                        visualization::rendering::ParseGpuBudget(gpu_budget.cast<std::string>());
                } else if (py::isinstance<py::int_>(gpu_budget) &&
                           !py::isinstance<py::bool_>(gpu_budget) &&
                           gpu_budget.cast<py::int_>() >= py::int_(0)) {
                    options.gpu_budget = gpu_budget.cast<uint64_t>();
                } else {
                    core::ThrowError(
                        "stream_splats: gpu_budget {} is neither bytes (an int >= 0, 0: the "
                        "default) nor a size such as '2G' or 'auto'",
                        py::repr(gpu_budget).cast<std::string>());
                }
                options.splat_budget = splat_budget;
                options.reads_per_step = reads_per_step;
                options.compact_storage =
                    compact_storage.value_or(s.renderer->Config().compact_storage);
                s.renderer->SplatRenderer().StreamSplats(InputPath(path), options);
            },
            py::arg("path"), py::arg("gpu_budget") = 0, py::arg("splat_budget") = 0,
            py::arg("reads_per_step") = 16, py::arg("compact_storage") = py::none(),
            "Streams a paged file (write_splat_pages, gs-convert --pages) as the splat scene "
            "(docs/streaming.md): its pages are read on a worker thread into a GPU pool of "
            "gpu_budget bytes (an int, or a str such as '512M' or '2G'; 0 or 'auto': 1 GiB, or "
            "what the device holds in one scene where that is less) for the view of each "
            "render; each render shows the pages read since the one before. splat_budget: nodes "
            "a cut may draw (0: what the pool holds). compact_storage: the pool at half precision "
            "(about 1.8 times the splats in gpu_budget; None: the renderer's compact_storage); "
            "the stream draws at its pool's precision. Raises Open3DError while splat clouds are "
            "held, for a refused file, or with the cpu backend (only vulkan streams).")
        .def(
            "stop_streaming",
            [](SplatScene& s) { return s.renderer->SplatRenderer().StopStreaming(); },
            "Ends the stream and frees its pool; False when there was none")
        .def_property_readonly(
            "stream_progress",
            [](const SplatScene& s) -> py::object {
                const auto p = s.renderer->SplatRenderer().GetStreamProgress();
                if (!p) return py::none();
                py::dict d;
                d["path"] = p->path;
                d["file_pages"] = p->file_pages;
                d["pool_pages"] = p->pool_pages;
                d["resident_pages"] = p->resident_pages;
                d["pages_read"] = p->pages_read;
                d["bytes_read"] = p->bytes_read;
                d["evictions"] = p->evictions;
                d["nodes_drawn"] = p->nodes_drawn;
                d["pages_wanted"] = p->pages_wanted;
                d["starved"] = p->starved;
                d["settled"] = p->settled;
                d["error"] = p->error;
                d["text"] = visualization::rendering::FormatStreamProgress(*p);
                return d;
            },
            "None when not streaming; else a dict as of the last render: file_pages, pool_pages, "
            "resident_pages, pages_read, bytes_read, evictions, nodes_drawn (by the newest cut), "
            "pages_wanted (pages that cut lacks), starved (the pool is full for this view), "
            "settled (nothing more will change for this view: the last render showed it all), "
            "error, and text (the viewer panel's line)")
        .def_property_readonly(
            "geometry_names", [](const SplatScene& s) { return s.renderer->Names(); },
            "The names, in the order they were added")
        .def(
            "set_background",
            [](SplatScene& s, const Eigen::Vector3d& rgb) { s.renderer->SetBackground(rgb); },
            py::arg("rgb"),
            "Linear RGB where nothing is drawn (default black: splat colours are then "
            "premultiplied)");
}

}  // namespace pybind
}  // namespace open3d
