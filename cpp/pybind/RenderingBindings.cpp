// visualization.rendering: OffscreenRenderer for splat scenes without a display (the splat
// backends alone, no Filament), RenderConfig knobs as properties, batches of cameras.
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
#include "PyPointCloud.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/MaterialRecord.h"
#include "open3d/visualization/rendering/filament/OffscreenRenderer.h"
#include "open3d/visualization/rendering/gaussian_splat/GaussianSplatRenderer.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

namespace {

using visualization::rendering::GaussianSplatRenderer;
using visualization::rendering::MaterialRecord;
using visualization::rendering::RenderConfig;
using visualization::rendering::RenderOutput;

constexpr uint64_t kView = 0;  // the renderer's one view

// The scene, its camera and its settings. Without meshes: the splat backend alone
// (GaussianSplatRenderer, no display needed). With `meshes`: the Filament OffscreenRenderer
// (meshes and splats composited by depth; needs an X server). Python's OffscreenRenderer and
// its `scene` share one of these.
class SplatOffscreen {
public:
    SplatOffscreen(int width, int height, const std::string& backend, bool meshes)
        : width_(width), height_(height) {
        if (width <= 0 || height <= 0) {
            core::ThrowError("OffscreenRenderer: size must be positive, got {}x{}", width, height);
        }
        if (backend != "vulkan" && backend != "cpu") {
            core::ThrowError("OffscreenRenderer: backend '{}' (vulkan or cpu)", backend);
        }
        if (!meshes) {
            renderer_ = std::make_unique<GaussianSplatRenderer>(backend);
            return;
        }
        visualization::rendering::Open3DSceneOptions options;
        options.backend = backend;
        try {
            filament_ = std::make_unique<visualization::rendering::OffscreenRenderer>(width, height,
                                                                                      options);
        } catch (const core::Open3DError& e) {
            core::ThrowError(
                "OffscreenRenderer(meshes=True) draws with Filament, which needs an X server "
                "(splats alone need none: leave meshes off): {}",
                e.what());
        }
    }

    bool HasMeshes() const { return filament_ != nullptr; }
    RenderConfig& Config() { return config_; }
    int Width() const { return width_; }
    int Height() const { return height_; }
    std::string BackendName() const {
        return filament_ ? filament_->GetScene()->GetScene().GetBackend().GetName()
                         : renderer_->GetBackendName();
    }
    const std::vector<std::string>& Names() const { return names_; }

    void AddCloud(const std::string& name, const t::geometry::PointCloud& cloud,
                  const std::optional<MaterialRecord>& material) {
        if (filament_) {
            if (material) {
                filament_->GetScene()->AddGeometry(name, cloud, *material);
            } else {
                filament_->GetScene()->AddGeometry(name, cloud);
            }
        } else {
            if (material && material->shader != visualization::rendering::kShaderGaussianSplat) {
                core::ThrowError(
                    "OffscreenRenderer: '{}' with shader '{}': without meshes=True only Gaussian "
                    "splat clouds are drawn",
                    name, material->shader);
            }
            renderer_->AddCloud(name, cloud);
        }
        names_.push_back(name);
    }
    void AddMesh(const std::string& name, const t::geometry::TriangleMesh& mesh,
                 const MaterialRecord& material) {
        if (!filament_) {
            core::ThrowError(
                "OffscreenRenderer: mesh '{}': meshes are drawn by Filament; create the renderer "
                "with meshes=True (needs an X server)",
                name);
        }
        filament_->GetScene()->AddGeometry(name, mesh, material);
        names_.push_back(name);
    }
    void UpdateCloud(const std::string& name, const t::geometry::PointCloud& cloud) {
        if (filament_) {
            filament_->GetScene()->UpdateGeometry(name, cloud);
        } else {
            renderer_->UpdateCloud(name, cloud);
        }
    }
    bool Remove(const std::string& name) {
        const bool removed =
            filament_ ? filament_->GetScene()->RemoveGeometry(name) : renderer_->RemoveCloud(name);
        std::erase(names_, name);
        return removed;
    }
    void Show(const std::string& name, bool show) {
        if (filament_) {
            filament_->GetScene()->ShowGeometry(name, show);
        } else {
            renderer_->ShowCloud(name, show);
        }
    }
    bool Has(const std::string& name) const {
        return filament_ ? filament_->GetScene()->HasGeometry(name) : renderer_->HasCloud(name);
    }
    void Clear() {
        if (filament_) {
            filament_->GetScene()->ClearGeometry();
        } else {
            renderer_->Clear();
        }
        names_.clear();
    }
    GaussianSplatRenderer& SplatRenderer() const {
        return filament_ ? filament_->GetScene()->GetScene().GetSplatRenderer() : *renderer_;
    }
    void SetBackground(const Eigen::Vector3d& rgb) {
        config_.background = rgb;
        if (filament_) {
            filament_->GetScene()->SetBackground(rgb.cast<float>().homogeneous());
        }
    }

    /// Uses the camera at the renderer's size.
    void SetCamera(const camera::PinholeCamera& camera) {
        camera_ = Sized(camera);
        has_camera_ = true;
    }
    const camera::PinholeCamera& Camera() const {
        if (!has_camera_) core::ThrowError("OffscreenRenderer: call setup_camera first");
        return camera_;
    }

    RenderOutput Render(bool expected_depth, bool median_depth) {
        const camera::PinholeCamera camera = Camera();
        RequireVisibleSplats();
        RenderOutput out;
        visualization::rendering::CompositeInputs inputs;
        inputs.expected_depth = expected_depth;
        inputs.median_depth = median_depth;
        py::gil_scoped_release release;
        renderer_->Prepare();
        renderer_->RenderGeometryStage(kView, camera, config_);
        renderer_->RenderCompositeStage(kView, out, inputs);
        return out;
    }

    /// Filament's frame: UInt8 [H, W, 3], or the view z Float32 [H, W, 1] with `depth`.
    t::geometry::Image RenderWithMeshes(bool depth) {
        const camera::PinholeCamera camera = Camera();
        // The knobs go to the scene's splat settings (background stays the view's).
        RenderConfig& splat = filament_->GetScene()->GetSplatConfig();
        splat.sh_degree = config_.sh_degree;
        splat.antialias = config_.antialias;
        splat.near_plane = config_.near_plane;
        splat.compact_storage = config_.compact_storage;
        filament_->SetupCamera(camera);
        py::gil_scoped_release release;
        return depth ? filament_->RenderToDepthImage(true) : filament_->RenderToImage();
    }

    /// Renders into `destination` (N x H x W x 4 elements of float32, or uint8 with `uint8`),
    /// which lies in `memory` when that is set (the device then copies into it directly).
    void RenderBatch(const std::vector<camera::PinholeCamera>& cameras, bool uint8,
                     uint8_t* destination,
                     const visualization::rendering::BatchHostMemory& memory = {}) {
        if (filament_) {
            core::ThrowError("render_batch: batches are for splat-only renderers (meshes=False)");
        }
        if (renderer_->IsStreaming()) {
            // A batch draws the pool as it stands and gives the stream no view.
            core::ThrowError(
                "render_batch: not while a stream runs (render_to_image streams for its view)");
        }
        std::vector<camera::PinholeCamera> sized;
        for (const camera::PinholeCamera& c : cameras) sized.push_back(Sized(c));
        RequireVisibleSplats();
        visualization::rendering::BatchOptions options;
        options.color_uint8 = uint8;
        options.color_destination = destination;
        options.color_memory = memory;
        py::gil_scoped_release release;
        renderer_->Prepare();
        // The batch replaces the view's sorted entries in the backend.
        renderer_->ReleaseView(kView);
        renderer_->GetBackend().RenderBatch(sized, config_, options);
    }

private:
    /// Validated, with its intrinsics scaled to the renderer's size when its size differs.
    camera::PinholeCamera Sized(const camera::PinholeCamera& camera) const {
        camera.Validate();
        return camera.width == width_ && camera.height == height_ ? camera
                                                                  : camera.Resized(width_, height_);
    }
    void RequireVisibleSplats() const {
        if (!renderer_->HasVisibleSplats()) {
            core::ThrowError("OffscreenRenderer: the scene has no visible splat cloud");
        }
    }

    int width_, height_;
    std::unique_ptr<GaussianSplatRenderer> renderer_;
    std::unique_ptr<visualization::rendering::OffscreenRenderer> filament_;
    std::vector<std::string> names_;
    RenderConfig config_;
    camera::PinholeCamera camera_;
    bool has_camera_ = false;
};

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

struct SplatScene {
    Offscreen renderer;
};

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
    py::class_<SplatScene>(m, "Scene",
                           "The geometry of an OffscreenRenderer, by name: Gaussian splat "
                           "clouds, and with meshes=True meshes and point clouds too")
        .def(
            "add_geometry",
            [](SplatScene& s, const std::string& name, const PyPointCloud& cloud,
               const std::optional<MaterialRecord>& material) {
                s.renderer->AddCloud(name, cloud.cloud, material);
            },
            py::arg("name"), py::arg("geometry"), py::arg("material") = py::none(),
            "Adds a copy of a cloud (a Gaussian splat cloud unless the material says otherwise); "
            "raises for a taken name or a cloud without the Gaussian attributes")
        .def(
            "add_geometry",
            [](SplatScene& s, const std::string& name, const t::geometry::TriangleMesh& mesh,
               const std::optional<MaterialRecord>& material) {
                s.renderer->AddMesh(name, mesh, material.value_or(MaterialRecord{}));
            },
            py::arg("name"), py::arg("geometry"), py::arg("material") = py::none(),
            "Adds a copy of a mesh (renderers made with meshes=True)")
        .def(
            "update_geometry",
            [](SplatScene& s, const std::string& name, const PyPointCloud& cloud) {
                s.renderer->UpdateCloud(name, cloud.cloud);
            },
            py::arg("name"), py::arg("geometry"))
        .def(
            "remove_geometry",
            [](SplatScene& s, const std::string& name) { return s.renderer->Remove(name); },
            py::arg("name"))
        .def(
            "show_geometry",
            [](SplatScene& s, const std::string& name, bool show) { s.renderer->Show(name, show); },
            py::arg("name"), py::arg("show"))
        .def(
            "has_geometry",
            [](const SplatScene& s, const std::string& name) { return s.renderer->Has(name); },
            py::arg("name"))
        .def(
            "clear_geometry", [](SplatScene& s) { s.renderer->Clear(); },
            "Removes every geometry and ends a stream")
        .def(
            "stream_splats",
            [](SplatScene& s, const std::string& path, const py::object& gpu_budget,
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
                s.renderer->SplatRenderer().StreamSplats(path, options);
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
        .def_property_readonly("geometry_names",
                               [](const SplatScene& s) { return s.renderer->Names(); })
        .def(
            "set_background",
            [](SplatScene& s, const Eigen::Vector3d& rgb) { s.renderer->SetBackground(rgb); },
            py::arg("rgb"),
            "Linear RGB where nothing is drawn (default black: splat colours are then "
            "premultiplied)");

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
