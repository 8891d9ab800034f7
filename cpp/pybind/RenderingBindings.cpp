// visualization.rendering.OffscreenRenderer: splat scenes rendered to numpy arrays without a
// display (the splat backends alone, no Filament), RenderConfig knobs as properties, batches
// of cameras (the scene's bindings: SceneBindings.cpp; the state: SplatOffscreen).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "Bindings.h"
#include "NumpyTensor.h"
#include "SplatOffscreen.h"
#include "open3d/core/Exception.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

namespace {

using visualization::rendering::RenderConfig;
using visualization::rendering::RenderOutput;

using Offscreen = std::shared_ptr<SplatOffscreen>;

// Arrays from OffscreenRenderer.batch_array own a BatchHostMemory through a capsule of this
// name at the root of their base chain; render_batch(out=) finds it there.
constexpr const char* kBatchMemoryCapsule = "open3d_gs.BatchHostMemory";

py::array BatchArray(const std::vector<py::ssize_t>& shape, bool uint8) {
    size_t bytes = uint8 ? 1 : 4;
    for (py::ssize_t d : shape) bytes *= static_cast<size_t>(d);
    auto* memory = new visualization::rendering::BatchHostMemory(bytes);
    // The PyObject* destructor form: pybind11 2.10 (Debian 12) names no void* one with a name.
    py::capsule owner(memory, kBatchMemoryCapsule, [](PyObject* capsule) {
        delete static_cast<visualization::rendering::BatchHostMemory*>(
            PyCapsule_GetPointer(capsule, kBatchMemoryCapsule));
    });
    if (uint8) return py::array_t<uint8_t>(shape, memory->Data(), owner);
    return py::array_t<float>(shape, reinterpret_cast<float*>(memory->Data()), owner);
}

// The BatchHostMemory an array's data lies in (a batch_array or a view of one), or none.
visualization::rendering::BatchHostMemory BatchMemoryOf(const py::array& array) {
    py::handle base = array.base();
    while (base && !base.is_none()) {
        if (PyCapsule_CheckExact(base.ptr())) {
            const char* name = PyCapsule_GetName(base.ptr());
            if (name != nullptr && std::string(name) == kBatchMemoryCapsule) {
                return *static_cast<visualization::rendering::BatchHostMemory*>(
                    PyCapsule_GetPointer(base.ptr(), name));
            }
            return {};
        }
        if (!py::isinstance<py::array>(base)) return {};
        base = py::reinterpret_borrow<py::array>(base).base();
    }
    return {};
}

py::array ColorArray(RenderOutput& out, const std::string& dtype) {
    if (dtype == "float32") return ArrayFromImage(std::move(out.color));
    return ArrayFromImage(out.color.SelectChannels(0, 3).ToUInt8());
}

int CheckShDegree(int degree) {
    if (degree < 0 || degree > 3) core::ThrowError("sh_degree {}: the cap is 0..3", degree);
    return degree;
}

void CheckDtype(const std::string& dtype) {
    if (dtype != "float32" && dtype != "uint8") {
        core::ThrowError("dtype '{}': float32 (premultiplied RGBA) or uint8 (RGB)", dtype);
    }
}

}  // namespace

void BindRendering(py::module_& m) {
    py::class_<SplatOffscreen, Offscreen>(
        m, "OffscreenRenderer",
        "Renders scenes to numpy arrays. Default: splat clouds only, drawn by the splat backend "
        "alone without a display: 'vulkan' (any Vulkan 1.3 device, lavapipe without a GPU) or "
        "'cpu' (the double-precision reference). meshes=True: Filament draws meshes and points "
        "and composites the splats by depth (needs an X server; 8-bit colour).")
        .def(py::init([](int width, int height, const std::string& backend, bool meshes,
                         int sh_degree, bool antialias, bool compact_storage, double near_plane) {
                 auto r = std::make_shared<SplatOffscreen>(width, height, backend, meshes);
                 r->Config().sh_degree = CheckShDegree(sh_degree);
                 r->Config().antialias = antialias;
                 r->Config().compact_storage = compact_storage;
                 r->Config().near_plane = near_plane;
                 r->Config().Validate();
                 return r;
             }),
             py::arg("width"), py::arg("height"), py::arg("backend") = "vulkan",
             py::arg("meshes") = false, py::kw_only(), py::arg("sh_degree") = 3,
             py::arg("antialias") = false, py::arg("compact_storage") = false,
             py::arg("near_plane") = RenderConfig{}.near_plane,
             "The knobs are keyword arguments and properties: sh_degree (cap, 0..3), "
             "antialias (Mip-Splatting's), compact_storage (Vulkan, half precision), "
             "near_plane")
        .def_property_readonly("scene", [](const Offscreen& r) { return SplatScene{r}; })
        .def_property_readonly("backend", &SplatOffscreen::BackendName)
        .def_property_readonly("meshes", &SplatOffscreen::HasMeshes)
        .def_property_readonly("width", &SplatOffscreen::Width)
        .def_property_readonly("height", &SplatOffscreen::Height)
        .def("setup_camera", &SplatOffscreen::SetCamera, py::arg("camera"),
             "Uses the camera; its intrinsics are scaled to the renderer's size when they differ")
        .def(
            "setup_camera",
            [](SplatOffscreen& r, const Eigen::Matrix3d& K, const Eigen::Matrix4d& extrinsic) {
                r.SetCamera(
                    camera::PinholeCamera::FromIntrinsic(K, extrinsic, r.Width(), r.Height()));
            },
            py::arg("intrinsic"), py::arg("extrinsic"),
            "OpenCV intrinsics (for this renderer's size) and a world-to-camera extrinsic")
        .def(
            "setup_camera",
            [](SplatOffscreen& r, double vertical_fov_deg, const Eigen::Vector3d& center,
               const Eigen::Vector3d& eye, const Eigen::Vector3d& up) {
                camera::LookAtCamera look;
                look.eye = eye;
                look.center = center;
                look.up = up;
                look.vertical_fov_deg = vertical_fov_deg;
                r.SetCamera(camera::PinholeCamera::FromLookAt(look, r.Width(), r.Height()));
            },
            py::arg("vertical_field_of_view"), py::arg("center"), py::arg("eye"), py::arg("up"))
        .def_property_readonly("camera", &SplatOffscreen::Camera)
        .def_property(
            "sh_degree", [](SplatOffscreen& r) { return r.Config().sh_degree; },
            [](SplatOffscreen& r, int v) { r.Config().sh_degree = CheckShDegree(v); },
            "SH degree cap, 0..3")
        .def_property(
            "antialias", [](SplatOffscreen& r) { return r.Config().antialias; },
            [](SplatOffscreen& r, bool v) { r.Config().antialias = v; })
        .def_property(
            "near_plane", [](SplatOffscreen& r) { return r.Config().near_plane; },
            [](SplatOffscreen& r, double v) { r.Config().near_plane = v; })
        .def_property(
            "compact_storage", [](SplatOffscreen& r) { return r.Config().compact_storage; },
            [](SplatOffscreen& r, bool v) { r.Config().compact_storage = v; },
            "Vulkan: half-precision splat storage (about half the memory, not exact)")
        .def(
            "render_to_image",
            [](SplatOffscreen& r, const std::optional<std::string>& requested) {
                const std::string dtype = requested.value_or(r.HasMeshes() ? "uint8" : "float32");
                CheckDtype(dtype);
                if (r.HasMeshes()) {
                    if (dtype != "uint8") {
                        core::ThrowError(
                            "render_to_image: with meshes=True the picture is 8-bit (Filament's "
                            "colour target): dtype 'uint8'");
                    }
                    return ArrayFromImage(r.RenderWithMeshes(false));
                }
                RenderOutput out = r.Render(false, false);
                return ColorArray(out, dtype);
            },
            py::arg("dtype") = py::none(),
            "float32 (the default without meshes): (H, W, 4) RGBA, premultiplied over a black "
            "background; uint8 (the default and only choice with meshes): (H, W, 3) RGB rounded "
            "to nearest")
        .def(
            "render_to_depth_image",
            [](SplatOffscreen& r, const std::string& kind) {
                if (kind != "expected" && kind != "median") {
                    core::ThrowError("render_to_depth_image: kind '{}' (expected or median)", kind);
                }
                if (r.HasMeshes()) {
                    // The nearer of the meshes' z and the splats' expected z (Filament's merge).
                    return ArrayFromImage(r.RenderWithMeshes(true), true);
                }
                RenderOutput out = r.Render(kind == "expected", kind == "median");
                return ArrayFromImage(
                    std::move(kind == "expected" ? out.depth_expected : out.depth_median), true);
            },
            py::arg("kind") = "expected",
            "(H, W) float32 view-space z: the alpha-weighted mean (expected) or where the "
            "accumulated alpha reaches one half (median); 0 where no splat is. With meshes: the "
            "nearer of the mesh's z and the splats' (kind is not used)")
        .def(
            "render_batch",
            [](SplatOffscreen& r, const std::vector<camera::PinholeCamera>& cameras,
               const std::string& dtype, std::optional<py::array> out) {
                CheckDtype(dtype);
                if (cameras.empty()) core::ThrowError("render_batch: no cameras");
                const bool uint8 = dtype == "uint8";
                const std::vector<py::ssize_t> shape = {py::ssize_t(cameras.size()), r.Height(),
                                                        r.Width(), 4};
                py::array images;
                if (out) {
                    // The caller's array, reused across calls: no fresh pages to fault in
                    // (a new 64-view float32 array at 800x800 is 655 MB).
                    const bool dtype_ok = uint8 ? py::isinstance<py::array_t<uint8_t>>(*out)
                                                : py::isinstance<py::array_t<float>>(*out);
                    const bool shape_ok =
                        out->ndim() == 4 && std::equal(shape.begin(), shape.end(), out->shape());
                    if (!dtype_ok || !shape_ok || !(out->flags() & py::array::c_style) ||
                        !out->writeable()) {
                        core::ThrowError(
                            "render_batch: out must be a writeable C-contiguous {} array of "
                            "shape ({}, {}, {}, 4)",
                            dtype, shape[0], shape[1], shape[2]);
                    }
                    images = *out;
                } else if (uint8) {
                    images = py::array_t<uint8_t>(shape);
                } else {
                    images = py::array_t<float>(shape);
                }
                // Rendered straight into the array: one copy from the device's readback buffer,
                // none on the host when it is a batch_array.
                r.RenderBatch(cameras, uint8, static_cast<uint8_t*>(images.mutable_data()),
                              BatchMemoryOf(images));
                return images;
            },
            py::arg("cameras"), py::arg("dtype") = "float32", py::arg("out") = py::none(),
            "(N, H, W, 4) for N cameras in one call: float32 premultiplied RGBA, or uint8 RGBA "
            "(the device's rounding); each equals render_to_image of that camera. `out`: an "
            "array of that shape and dtype to render into (reused across calls, it saves "
            "allocating and faulting in fresh memory each time); one from batch_array is "
            "written by the GPU directly (Vulkan), with no copy on the host")
        .def(
            "batch_array",
            [](SplatOffscreen& r, int count, const std::string& dtype) {
                CheckDtype(dtype);
                if (count < 1) core::ThrowError("batch_array: count must be >= 1, not {}", count);
                return BatchArray({py::ssize_t(count), r.Height(), r.Width(), 4}, dtype == "uint8");
            },
            py::arg("count"), py::arg("dtype") = "float32",
            "An uninitialised (count, H, W, 4) array for render_batch(out=...): page-aligned "
            "host memory that the Vulkan backend lets the GPU write directly (no copy on the "
            "host; the fastest readback). Any renderer of this size accepts it");
}

}  // namespace pybind
}  // namespace open3d
