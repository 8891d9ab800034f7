// visualization.rendering.OffscreenRenderer: splat scenes rendered to numpy arrays without a
// display (the splat backends alone, no Filament), RenderConfig knobs as properties, batches
// of cameras (the scene's bindings: SceneBindings.cpp; the state: SplatOffscreen).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "Bindings.h"
#include "NumpyTensor.h"
#include "PyCamera.h"
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

void CheckDtype(const std::string& dtype) {
    if (dtype != "float32" && dtype != "uint8") {
        core::ThrowError("dtype '{}': float32 or uint8", dtype);
    }
}

// One rule for every colour array: float32 is RGBA (premultiplied over a black background),
// uint8 is RGB (Open3D's render_to_image); `alpha` asks for the other.
int Channels(const std::string& dtype, std::optional<bool> alpha) {
    CheckDtype(dtype);
    return alpha.value_or(dtype == "float32") ? 4 : 3;
}

py::array ColorArray(RenderOutput& out, const std::string& dtype, int channels) {
    t::geometry::Image color =
        channels == 4 ? std::move(out.color) : out.color.SelectChannels(0, channels);
    if (dtype == "uint8") color = color.ToUInt8();
    return ArrayFromImage(std::move(color));
}

// A view-z image (0 where nothing is) in the convention asked for: None, as it is (this
// package's default since it began); True, Open3D's z_in_view_space (infinity where nothing
// is); False, Open3D's normalised depth, 0 at the near plane to 1 at the far plane, which is
// here infinitely far: 1 - near / z (the depth buffer of such a projection), 1 where nothing
// is.
py::array DepthArray(t::geometry::Image&& z, std::optional<bool> z_in_view_space, double near) {
    if (z_in_view_space) {
        float* d = z.Data<float>();
        const float n = static_cast<float>(near);
        for (int64_t i = 0; i < z.NumPixels(); ++i) {
            if (!(d[i] > 0.0f)) {
                d[i] = *z_in_view_space ? std::numeric_limits<float>::infinity() : 1.0f;
            } else if (!*z_in_view_space) {
                d[i] = std::clamp(1.0f - n / d[i], 0.0f, 1.0f);
            }
        }
    }
    return ArrayFromImage(std::move(z), true);
}

py::array RenderDepth(SplatOffscreen& r, const std::string& kind,
                      std::optional<bool> z_in_view_space) {
    if (kind != "expected" && kind != "median") {
        core::ThrowError("render_to_depth_image: kind '{}' (expected or median)", kind);
    }
    const double near = r.Config().near_plane;
    if (r.HasMeshes()) {
        // The nearer of the meshes' z and the splats' expected z (Filament's merge).
        return DepthArray(r.RenderWithMeshes(true), z_in_view_space, near);
    }
    RenderOutput out = r.Render(kind == "expected", kind == "median");
    return DepthArray(std::move(kind == "expected" ? out.depth_expected : out.depth_median),
                      z_in_view_space, near);
}

// The RGB of `rgba` ([count, 4] elements of T) into `rgb` ([count, 3]).
template <typename T>
void DropAlpha(const T* rgba, T* rgb, int64_t count) {
    for (int64_t i = 0; i < count; ++i) {
        for (int c = 0; c < 3; ++c) rgb[3 * i + c] = rgba[4 * i + c];
    }
}

// The size of (intrinsic, extrinsic) cameras: the renderer's unless given (both or neither).
std::pair<int, int> CameraSize(const SplatOffscreen& r, std::optional<int> width,
                               std::optional<int> height) {
    if (width.has_value() != height.has_value()) {
        core::ThrowError("setup_camera: give width and height both, or neither");
    }
    return {width.value_or(r.Width()), height.value_or(r.Height())};
}

int CheckShDegree(int degree) {
    if (degree < 0 || degree > 3) core::ThrowError("sh_degree {}: the cap is 0..3", degree);
    return degree;
}

}  // namespace

void BindRendering(py::module_& m) {
    py::class_<SplatOffscreen, Offscreen>(
        m, "OffscreenRenderer",
        "Renders scenes to numpy arrays. Default: splat clouds only, drawn by the splat backend "
        "alone without a display: 'vulkan' (any Vulkan 1.3 device, lavapipe without a GPU) or "
        "'cpu' (the double-precision reference). meshes=True: Filament draws meshes and points "
        "and composites the splats by depth (on the X server of DISPLAY, else headless on EGL; "
        "8-bit colour).")
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
        .def_property_readonly(
            "scene", [](const Offscreen& r) { return SplatScene{r}; },
            "The geometry by name (add_geometry, set_background, stream_splats, ...)")
        .def_property_readonly("backend", &SplatOffscreen::BackendName,
                               "The splat backend's name: 'vulkan' or 'cpu'")
        .def_property_readonly("meshes", &SplatOffscreen::HasMeshes,
                               "Whether Filament draws (meshes=True)")
        .def_property_readonly("width", &SplatOffscreen::Width, "Picture width in pixels")
        .def_property_readonly("height", &SplatOffscreen::Height, "Picture height in pixels")
        .def("setup_camera", &SplatOffscreen::SetCamera, py::arg("camera"), py::kw_only(),
             py::arg("rescale") = false,
             "Uses the camera. One of another size is refused unless rescale=True, which "
             "scales its intrinsics to the renderer's size (another aspect ratio stretches the "
             "picture)")
        .def(
            "setup_camera",
            [](SplatOffscreen& r, const Eigen::Matrix3d& K, const Eigen::Matrix4d& extrinsic,
               std::optional<int> width, std::optional<int> height, bool rescale) {
                CheckIntrinsicMatrix(K, "setup_camera");
                const auto [w, h] = CameraSize(r, width, height);
                r.SetCamera(camera::PinholeCamera::FromIntrinsic(K, extrinsic, w, h), rescale);
            },
            py::arg("intrinsic_matrix"), py::arg("extrinsic_matrix"),
            py::arg("intrinsic_width_px") = py::none(), py::arg("intrinsic_height_px") = py::none(),
            py::kw_only(), py::arg("rescale") = false,
            "Open3D's setup_camera(intrinsic_matrix, extrinsic_matrix, width, height): OpenCV "
            "intrinsics K (no skew) for an image of that size (default: the renderer's) and a "
            "world-to-camera extrinsic. Another size than the renderer's is refused unless "
            "rescale=True")
        .def(
            "setup_camera",
            [](SplatOffscreen& r, const PinholeCameraIntrinsic& intrinsic,
               const Eigen::Matrix4d& extrinsic, std::optional<int> width,
               std::optional<int> height, bool rescale) {
                if ((width && *width != intrinsic.width) ||
                    (height && *height != intrinsic.height)) {
                    core::ThrowError(
                        "setup_camera: width and height {}x{} differ from the intrinsic's {}x{}",
                        width.value_or(intrinsic.width), height.value_or(intrinsic.height),
                        intrinsic.width, intrinsic.height);
                }
                r.SetCamera(CameraFromIntrinsic(intrinsic, extrinsic), rescale);
            },
            py::arg("intrinsics"), py::arg("extrinsic_matrix"),
            py::arg("intrinsic_width_px") = py::none(), py::arg("intrinsic_height_px") = py::none(),
            py::kw_only(), py::arg("rescale") = false,
            "Open3D's setup_camera(PinholeCameraIntrinsic, extrinsic_matrix): the intrinsic's "
            "size must be the renderer's unless rescale=True")
        .def(
            "setup_camera",
            [](SplatOffscreen& r, double vertical_fov_deg, const Eigen::Vector3d& center,
               const Eigen::Vector3d& eye, const Eigen::Vector3d& up) {
                camera::LookAtCamera look;
                look.eye = eye;
                look.center = center;
                look.up = up;
                look.vertical_fov_deg = vertical_fov_deg;
                r.SetCamera(camera::PinholeCamera::FromLookAt(look, r.Width(), r.Height()), false);
            },
            py::arg("vertical_field_of_view"), py::arg("center"), py::arg("eye"), py::arg("up"),
            "Open3D's look-at form: a vertical field of view in degrees, the point looked at, "
            "the eye and the up direction, at the renderer's size")
        .def_property_readonly("camera", &SplatOffscreen::Camera,
                               "The camera in use, at the renderer's size (a PinholeCamera)")
        .def_property(
            "sh_degree", [](SplatOffscreen& r) { return r.Config().sh_degree; },
            [](SplatOffscreen& r, int v) { r.Config().sh_degree = CheckShDegree(v); },
            "SH degree cap, 0..3")
        .def_property(
            "antialias", [](SplatOffscreen& r) { return r.Config().antialias; },
            [](SplatOffscreen& r, bool v) { r.Config().antialias = v; },
            "Mip-Splatting's antialias, for clouds trained with it")
        .def_property(
            "near_plane", [](SplatOffscreen& r) { return r.Config().near_plane; },
            [](SplatOffscreen& r, double v) { r.Config().near_plane = v; },
            "Splats nearer than this view z are culled (3DGS: 0.2); the 0 of normalised depth")
        .def_property(
            "compact_storage", [](SplatOffscreen& r) { return r.Config().compact_storage; },
            [](SplatOffscreen& r, bool v) { r.Config().compact_storage = v; },
            "Vulkan: half-precision splat storage (about half the memory, not exact)")
        .def(
            "render_to_image",
            [](SplatOffscreen& r, const std::optional<std::string>& requested,
               std::optional<bool> alpha) {
                const std::string dtype = requested.value_or(r.HasMeshes() ? "uint8" : "float32");
                const int channels = Channels(dtype, alpha);
                if (r.HasMeshes()) {
                    if (dtype != "uint8" || channels != 3) {
                        core::ThrowError(
                            "render_to_image: with meshes=True the picture is 8-bit RGB "
                            "(Filament's colour target): dtype 'uint8' without alpha");
                    }
                    return ArrayFromImage(r.RenderWithMeshes(false));
                }
                RenderOutput out = r.Render(false, false);
                return ColorArray(out, dtype, channels);
            },
            py::arg("dtype") = py::none(), py::kw_only(), py::arg("alpha") = py::none(),
            "The picture of the camera. float32 (the default without meshes): (H, W, 4) RGBA, "
            "rgb = C + T * background and a = 1 - T (premultiplied RGBA when the background is "
            "black, the default). uint8 (the default and only choice with meshes): (H, W, 3) "
            "RGB rounded to nearest, as Open3D's. alpha=True / False asks for RGBA / RGB "
            "instead (without meshes); render_batch follows the same rule")
        .def(
            "render_to_depth_image",
            [](SplatOffscreen& r, const std::string& kind, std::optional<bool> z_in_view_space) {
                return RenderDepth(r, kind, z_in_view_space);
            },
            py::arg("kind") = "expected", py::kw_only(), py::arg("z_in_view_space") = py::none(),
            "(H, W) float32 depth of the splats: the alpha-weighted mean of their view z "
            "(kind 'expected') or where the accumulated alpha reaches one half ('median'). "
            "z_in_view_space None (the default, as before): view z, 0 where no splat is. True "
            "(Open3D's): view z, infinity where nothing is. False (Open3D's normalised depth): "
            "0 at the near plane to 1 at the far plane, infinitely far here: 1 - near_plane / "
            "z, 1 where nothing is. With meshes: the nearer of the mesh's z and the splats' "
            "(kind is not used)")
        .def(
            "render_to_depth_image",
            [](SplatOffscreen& r, bool z_in_view_space, const std::string& kind) {
                return RenderDepth(r, kind, z_in_view_space);
            },
            py::arg("z_in_view_space"), py::arg("kind") = "expected",
            "Open3D's positional form, render_to_depth_image(True): see the first form")
        .def(
            "render_to_id_image",
            [](SplatOffscreen& r) {
                py::array ids = ArrayFromImage(r.RenderSplatId(), true);
                return ids.attr("reshape")(r.Height(), r.Width());
            },
            "(H, W) int32: at each pixel the splat that contributes most to it (the largest "
            "blend weight alpha T, the first of equal ones front to back), as its index in the "
            "renderer's scene (its geometries in name order, one after another); -1 where no "
            "splat is. locate_splat(id) gives the geometry and the index in it. The same on "
            "the cpu and vulkan backends (docs/editing.md \"ID images\"); not with meshes=True")
        .def(
            "locate_splat",
            [](SplatOffscreen& r, int64_t id) -> py::object {
                const auto where = r.SplatRenderer().LocateSplat(id);
                if (!where) return py::none();
                return py::make_tuple(where->first, where->second);
            },
            py::arg("id"),
            "(geometry name, index in that geometry) of an ID from render_to_id_image, as the "
            "scene stood at the last render; None for -1")
        .def(
            "render_batch",
            [](SplatOffscreen& r, const std::vector<camera::PinholeCamera>& cameras,
               const std::string& dtype, std::optional<py::array> out, std::optional<bool> alpha,
               bool rescale) {
                CheckDtype(dtype);
                if (cameras.empty()) core::ThrowError("render_batch: no cameras");
                const bool uint8 = dtype == "uint8";
                // An `out` of 3 or 4 channels says which it wants when alpha is not given.
                if (out && !alpha && out->ndim() == 4 &&
                    (out->shape(3) == 3 || out->shape(3) == 4)) {
                    alpha = out->shape(3) == 4;
                }
                const int channels = Channels(dtype, alpha);
                const std::vector<py::ssize_t> shape = {py::ssize_t(cameras.size()), r.Height(),
                                                        r.Width(), channels};
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
                            "shape ({}, {}, {}, {})",
                            dtype, shape[0], shape[1], shape[2], channels);
                    }
                    images = *out;
                } else if (uint8) {
                    images = py::array_t<uint8_t>(shape);
                } else {
                    images = py::array_t<float>(shape);
                }
                if (channels == 4) {
                    // Rendered straight into the array: one copy from the device's readback
                    // buffer, none on the host when it is a batch_array.
                    r.RenderBatch(cameras, rescale, uint8,
                                  static_cast<uint8_t*>(images.mutable_data()),
                                  BatchMemoryOf(images));
                    return images;
                }
                // RGB: the device writes RGBA, so the alpha is dropped on the host.
                std::vector<py::ssize_t> rgba_shape = shape;
                rgba_shape[3] = 4;
                py::array rgba = uint8 ? py::array(py::array_t<uint8_t>(rgba_shape))
                                       : py::array(py::array_t<float>(rgba_shape));
                r.RenderBatch(cameras, rescale, uint8, static_cast<uint8_t*>(rgba.mutable_data()));
                const int64_t pixels = int64_t(cameras.size()) * r.Height() * r.Width();
                py::gil_scoped_release release;
                if (uint8) {
                    DropAlpha(static_cast<const uint8_t*>(rgba.data()),
                              static_cast<uint8_t*>(images.mutable_data()), pixels);
                } else {
                    DropAlpha(static_cast<const float*>(rgba.data()),
                              static_cast<float*>(images.mutable_data()), pixels);
                }
                return images;
            },
            py::arg("cameras"), py::arg("dtype") = "float32", py::arg("out") = py::none(),
            py::kw_only(), py::arg("alpha") = py::none(), py::arg("rescale") = false,
            "(N, H, W, C) for N cameras in one call, by render_to_image's rule: float32 RGBA "
            "(premultiplied over black), uint8 RGB; alpha=True / False asks for the other (an "
            "`out` of 4 or 3 channels says it too). Each image equals render_to_image of its "
            "camera (uint8: the device's rounding, within one level). Cameras of another size "
            "are refused unless rescale=True. `out`: an array of that shape and dtype to "
            "render into (reused across calls it saves allocating and faulting in fresh "
            "memory); a 4-channel one from batch_array is written by the GPU directly "
            "(Vulkan), with no copy on the host: the fastest path, uint8 RGBA included")
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
            "host; the fastest readback). RGBA in both dtypes, as the device writes it. Any "
            "renderer of this size accepts it");
}

}  // namespace pybind
}  // namespace open3d
