// camera: PinholeCamera from cameras.json, from OpenCV intrinsics and extrinsics, from a
// look-at; the 3DGS convention (x right, y down, z forward) throughout.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fmt/format.h>

#include <filesystem>
#include <string>
#include <vector>

#include "Bindings.h"
#include "PathArgs.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/camera/PinholeCamera.h"
#include "open3d/core/Exception.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

void BindCamera(py::module_& m) {
    using camera::PinholeCamera;
    py::class_<PinholeCamera>(
        m, "PinholeCamera",
        "Intrinsics and a world-to-camera extrinsic (OpenCV / 3DGS convention: x right, y "
        "down, z forward). A world point p projects to c = R p + t, then to the pixel "
        "(fx c.x / c.z + cx, fy c.y / c.z + cy).")
        .def(py::init([](int width, int height, double fx, double fy, double cx, double cy,
                         const Eigen::Matrix4d& world_to_camera) {
                 PinholeCamera c;
                 c.width = width;
                 c.height = height;
                 c.fx = fx;
                 c.fy = fy;
                 c.cx = cx;
                 c.cy = cy;
                 c.world_to_camera = world_to_camera;
                 c.Validate();
                 return c;
             }),
             py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"),
             py::arg("cy"), py::arg("world_to_camera") = Eigen::Matrix4d::Identity())
        .def_static(
            "from_intrinsics_extrinsics",
            [](const Eigen::Matrix3d& K, const Eigen::Matrix4d& extrinsic, int width, int height) {
                if (K(0, 1) != 0.0 || K(1, 0) != 0.0 || K(2, 0) != 0.0 || K(2, 1) != 0.0 ||
                    K(2, 2) != 1.0) {
                    core::ThrowError(
                        "from_intrinsics_extrinsics: K must be [[fx, 0, cx], [0, fy, cy], [0, 0, "
                        "1]] (no skew)");
                }
                return PinholeCamera::FromIntrinsic(K, extrinsic, width, height);
            },
            py::arg("intrinsic"), py::arg("extrinsic"), py::arg("width"), py::arg("height"),
            "OpenCV: K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], extrinsic = world-to-camera "
            "[R | t; 0 0 0 1]")
        .def_static(
            "look_at",
            [](const Eigen::Vector3d& eye, const Eigen::Vector3d& center, const Eigen::Vector3d& up,
               double vertical_fov_deg, int width, int height) {
                camera::LookAtCamera look;
                look.eye = eye;
                look.center = center;
                look.up = up;
                look.vertical_fov_deg = vertical_fov_deg;
                return PinholeCamera::FromLookAt(look, width, height);
            },
            py::arg("eye"), py::arg("center"), py::arg("up"), py::arg("vertical_fov_deg"),
            py::arg("width"), py::arg("height"))
        .def_readwrite("width", &PinholeCamera::width)
        .def_readwrite("height", &PinholeCamera::height)
        .def_readwrite("fx", &PinholeCamera::fx)
        .def_readwrite("fy", &PinholeCamera::fy)
        .def_readwrite("cx", &PinholeCamera::cx)
        .def_readwrite("cy", &PinholeCamera::cy)
        .def_readwrite("world_to_camera", &PinholeCamera::world_to_camera)
        .def_property_readonly("intrinsic_matrix",
                               [](const PinholeCamera& c) {
                                   Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
                                   K(0, 0) = c.fx;
                                   K(1, 1) = c.fy;
                                   K(0, 2) = c.cx;
                                   K(1, 2) = c.cy;
                                   return K;
                               })
        .def("get_center", &PinholeCamera::GetCenter, "The camera centre in world coordinates")
        .def("resized", &PinholeCamera::Resized, py::arg("width"), py::arg("height"),
             "The same view at another image size (focal lengths and principal point scale)")
        .def("__repr__", [](const PinholeCamera& c) {
            return fmt::format("PinholeCamera({}x{}, fx={}, fy={}, cx={}, cy={})", c.width,
                               c.height, c.fx, c.fy, c.cx, c.cy);
        });

    py::class_<camera::CameraView>(m, "CameraView", "One entry of a 3DGS cameras.json")
        .def_readonly("id", &camera::CameraView::id)
        .def_readonly("img_name", &camera::CameraView::img_name)
        .def_readonly("camera", &camera::CameraView::camera);
    m.def(
        "read_cameras_json",
        [](const std::filesystem::path& filename) {
            return camera::ReadCamerasJson(InputPath(filename));
        },
        py::arg("filename"),
        "Every view of a 3DGS cameras.json (a str or os.PathLike), in file order; raises "
        "naming the file, the entry and the field for malformed input, and "
        "Open3DFileNotFoundError (also a FileNotFoundError) for a missing file.");
}

}  // namespace pybind
}  // namespace open3d
