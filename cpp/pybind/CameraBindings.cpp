// camera: PinholeCamera from cameras.json, from OpenCV intrinsics and extrinsics, from a
// look-at; the 3DGS convention (x right, y down, z forward) throughout.
#include <pybind11/eigen.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <fmt/format.h>

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "Bindings.h"
#include "PathArgs.h"
#include "PyCamera.h"
#include "open3d/camera/CameraPath.h"
#include "open3d/camera/CamerasJson.h"
#include "open3d/camera/PinholeCamera.h"
#include "open3d/core/Exception.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

void CheckIntrinsicMatrix(const Eigen::Matrix3d& K, const char* what) {
    if (K(0, 1) != 0.0 || K(1, 0) != 0.0 || K(2, 0) != 0.0 || K(2, 1) != 0.0 || K(2, 2) != 1.0) {
        core::ThrowError("{}: K must be [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] (no skew)", what);
    }
}

camera::PinholeCamera CameraFromIntrinsic(const PinholeCameraIntrinsic& intrinsic,
                                          const Eigen::Matrix4d& extrinsic) {
    if (intrinsic.width <= 0 || intrinsic.height <= 0) {
        core::ThrowError("PinholeCameraIntrinsic: size {}x{} was not set (width, height > 0)",
                         intrinsic.width, intrinsic.height);
    }
    CheckIntrinsicMatrix(intrinsic.intrinsic_matrix, "PinholeCameraIntrinsic");
    return camera::PinholeCamera::FromIntrinsic(intrinsic.intrinsic_matrix, extrinsic,
                                                intrinsic.width, intrinsic.height);
}

void BindCamera(py::module_& m) {
    using camera::PinholeCamera;
    py::class_<PinholeCameraIntrinsic>(
        m, "PinholeCameraIntrinsic",
        "Open3D's intrinsics: an image size and K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]] "
        "(pixels; the 3DGS / OpenCV convention of PinholeCamera). "
        "OffscreenRenderer.setup_camera(intrinsic, extrinsic) takes it.")
        .def(py::init<>(), "Unset: width and height -1, K zero (Open3D's default)")
        .def(py::init([](int width, int height, double fx, double fy, double cx, double cy) {
                 PinholeCameraIntrinsic i;
                 i.width = width;
                 i.height = height;
                 i.intrinsic_matrix << fx, 0, cx, 0, fy, cy, 0, 0, 1;
                 return i;
             }),
             py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"),
             py::arg("cy"), "Open3D's PinholeCameraIntrinsic(width, height, fx, fy, cx, cy)")
        .def(py::init([](int width, int height, const Eigen::Matrix3d& K) {
                 CheckIntrinsicMatrix(K, "PinholeCameraIntrinsic");
                 return PinholeCameraIntrinsic{width, height, K};
             }),
             py::arg("width"), py::arg("height"), py::arg("intrinsic_matrix"),
             "From an image size and a 3x3 K without skew")
        .def_readwrite("width", &PinholeCameraIntrinsic::width, "Image width in pixels")
        .def_readwrite("height", &PinholeCameraIntrinsic::height, "Image height in pixels")
        .def_readwrite("intrinsic_matrix", &PinholeCameraIntrinsic::intrinsic_matrix,
                       "K, float64 (3, 3)")
        .def(
            "get_focal_length",
            [](const PinholeCameraIntrinsic& i) {
                return std::make_pair(i.intrinsic_matrix(0, 0), i.intrinsic_matrix(1, 1));
            },
            "(fx, fy)")
        .def(
            "get_principal_point",
            [](const PinholeCameraIntrinsic& i) {
                return std::make_pair(i.intrinsic_matrix(0, 2), i.intrinsic_matrix(1, 2));
            },
            "(cx, cy)")
        .def(
            "set_intrinsics",
            [](PinholeCameraIntrinsic& i, int width, int height, double fx, double fy, double cx,
               double cy) {
                i.width = width;
                i.height = height;
                i.intrinsic_matrix << fx, 0, cx, 0, fy, cy, 0, 0, 1;
            },
            py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"),
            py::arg("cy"), "Sets every value, as Open3D's")
        .def(
            "__repr__",
            [](const PinholeCameraIntrinsic& i) {
                return fmt::format("PinholeCameraIntrinsic({}x{}, fx={}, fy={}, cx={}, cy={})",
                                   i.width, i.height, i.intrinsic_matrix(0, 0),
                                   i.intrinsic_matrix(1, 1), i.intrinsic_matrix(0, 2),
                                   i.intrinsic_matrix(1, 2));
            },
            "The size and the four values");

    py::class_<PinholeCamera>(
        m, "PinholeCamera",
        "Intrinsics and a world-to-camera extrinsic (OpenCV / 3DGS convention: x right, y "
        "down, z forward). A world point p projects to c = R p + t, then to the pixel "
        "(fx c.x / c.z + cx, fy c.y / c.z + cy).")
        .def(py::init([](int width, int height, double fx, double fy, double cx, double cy,
                         const std::optional<Eigen::Matrix4d>& world_to_camera) {
                 PinholeCamera c;
                 c.width = width;
                 c.height = height;
                 c.fx = fx;
                 c.fy = fy;
                 c.cx = cx;
                 c.cy = cy;
                 c.world_to_camera = world_to_camera.value_or(Eigen::Matrix4d::Identity());
                 c.Validate();
                 return c;
             }),
             py::arg("width"), py::arg("height"), py::arg("fx"), py::arg("fy"), py::arg("cx"),
             py::arg("cy"), py::arg("world_to_camera") = py::none(),
             "A camera of an image size, focal lengths and principal point in pixels, and a "
             "world-to-camera extrinsic (default: the identity)")
        .def_static(
            "from_intrinsics_extrinsics",
            [](const Eigen::Matrix3d& K, const Eigen::Matrix4d& extrinsic, int width, int height) {
                CheckIntrinsicMatrix(K, "from_intrinsics_extrinsics");
                return PinholeCamera::FromIntrinsic(K, extrinsic, width, height);
            },
            py::arg("intrinsic"), py::arg("extrinsic"), py::arg("width"), py::arg("height"),
            "OpenCV: K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], extrinsic = world-to-camera "
            "[R | t; 0 0 0 1]")
        .def_static("from_intrinsics_extrinsics", &CameraFromIntrinsic, py::arg("intrinsic"),
                    py::arg("extrinsic"),
                    "From Open3D's PinholeCameraIntrinsic (its size) and a world-to-camera "
                    "extrinsic")
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
            py::arg("width"), py::arg("height"),
            "A camera at eye looking at center, up up in the image, with a vertical field of "
            "view in degrees")
        .def_readwrite("width", &PinholeCamera::width, "Image width in pixels")
        .def_readwrite("height", &PinholeCamera::height, "Image height in pixels")
        .def_readwrite("fx", &PinholeCamera::fx, "Focal length in pixels along x")
        .def_readwrite("fy", &PinholeCamera::fy, "Focal length in pixels along y")
        .def_readwrite("cx", &PinholeCamera::cx, "Principal point x in pixels")
        .def_readwrite("cy", &PinholeCamera::cy, "Principal point y in pixels")
        .def_readwrite("world_to_camera", &PinholeCamera::world_to_camera,
                       "The extrinsic, float64 (4, 4): c = R p + t")
        .def_property_readonly(
            "intrinsic_matrix",
            [](const PinholeCamera& c) {
                Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
                K(0, 0) = c.fx;
                K(1, 1) = c.fy;
                K(0, 2) = c.cx;
                K(1, 2) = c.cy;
                return K;
            },
            "K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], float64 (3, 3)")
        .def("get_center", &PinholeCamera::GetCenter, "The camera centre in world coordinates")
        .def("resized", &PinholeCamera::Resized, py::arg("width"), py::arg("height"),
             "The same view at another image size (focal lengths and principal point scale)")
        .def(
            "__repr__",
            [](const PinholeCamera& c) {
                return fmt::format("PinholeCamera({}x{}, fx={}, fy={}, cx={}, cy={})", c.width,
                                   c.height, c.fx, c.fy, c.cx, c.cy);
            },
            "The size and the intrinsics");

    py::class_<camera::CameraView>(m, "CameraView", "One entry of a 3DGS cameras.json")
        .def_readonly("id", &camera::CameraView::id, "The entry's id")
        .def_readonly("img_name", &camera::CameraView::img_name, "The name of the training image")
        .def_readonly("camera", &camera::CameraView::camera, "The view as a PinholeCamera")
        .def_readonly("time", &camera::CameraView::time,
                      "Seconds on a camera path (the optional 'time' field), or None");
    m.def(
        "read_cameras_json",
        [](const std::filesystem::path& filename) {
            return camera::ReadCamerasJson(InputPath(filename));
        },
        py::arg("filename"),
        "Every view of a 3DGS cameras.json (a str or os.PathLike), in file order; raises "
        "naming the file, the entry and the field for malformed input, and "
        "Open3DFileNotFoundError (also a FileNotFoundError) for a missing file.");

    py::class_<camera::CameraPath>(
        m, "CameraPath",
        "Keyframed cameras and the cameras between them (docs/camera-paths.md): centripetal "
        "Catmull-Rom centres, squad rotations, fields of view linear; a keyframe's time gives "
        "its camera exactly")
        .def(py::init([](const std::vector<double>& times,
                         const std::vector<camera::PinholeCamera>& cameras) {
                 if (times.size() != cameras.size()) {
                     core::ThrowError("CameraPath: {} times for {} cameras", times.size(),
                                      cameras.size());
                 }
                 std::vector<camera::CameraKeyframe> keyframes;
                 for (size_t i = 0; i < times.size(); ++i)
                     keyframes.push_back({times[i], cameras[i]});
                 return camera::CameraPath(std::move(keyframes));
             }),
             py::arg("times"), py::arg("cameras"),
             "A path through cameras (PinholeCamera, one image size) at times in seconds, "
             "strictly increasing")
        .def_static(
            "from_cameras_json",
            [](const std::filesystem::path& filename, double seconds_per_keyframe) {
                return camera::CameraPath::FromViews(camera::ReadCamerasJson(InputPath(filename)),
                                                     seconds_per_keyframe);
            },
            py::arg("filename"),
            py::arg("seconds_per_keyframe") = camera::kDefaultSecondsPerKeyframe,
            "A cameras.json's views as keyframes: at their 'time' fields, or "
            "seconds_per_keyframe apart")
        .def_property_readonly("duration", &camera::CameraPath::GetDuration, "Seconds")
        .def("at", &camera::CameraPath::At, py::arg("time"),
             "The camera at a time in seconds (clamped to the path)")
        .def(
            "frames", [](const camera::CameraPath& path, double fps) { return path.Frames(fps); },
            py::arg("fps") = 30.0,
            "The cameras at start + i / fps for i = 0 .. floor(duration * fps), both ends; "
            "render them with OffscreenRenderer.render_batch");
}

}  // namespace pybind
}  // namespace open3d
