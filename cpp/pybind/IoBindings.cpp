// t.io: read_point_cloud / write_point_cloud in every format the library knows, and the paged
// file a renderer streams (write_splat_pages).
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>
#include <memory>
#include <string>

#include "Bindings.h"
#include "PathArgs.h"
#include "PyPointCloud.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/SplatHierarchy.h"
#include "open3d/t/io/PointCloudIO.h"
#include "open3d/t/io/SplatPageFile.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

void BindIo(py::module_& m) {
    m.def(
        "read_point_cloud",
        [](const std::filesystem::path& filename, bool drop_non_finite) {
            auto cloud = std::make_shared<PyPointCloud>();
            t::io::ReadPointCloudOptions options;
            options.drop_non_finite = drop_non_finite;
            const std::string path = InputPath(filename);
            py::gil_scoped_release release;
            t::io::ReadPointCloud(path, cloud->cloud, options);
            return cloud;
        },
        py::arg("filename"), py::arg("drop_non_finite") = false,
        "Reads a splat file of any supported format (detected by content: .ply, "
        ".compressed.ply, .splat, .spz, .sog or a SOG folder, .gltf, .glb, .ksplat); filename "
        "is a str or an os.PathLike. Raises Open3DError naming the file and the problem "
        "(Open3DFileNotFoundError, also a FileNotFoundError, when nothing is there); "
        "non-finite values are refused unless drop_non_finite drops their splats.");
    m.def(
        "write_point_cloud",
        [](const std::filesystem::path& filename, const PyPointCloud& cloud,
           const std::string& ply_format) {
            t::io::WritePointCloudOptions options;
            if (ply_format == "binary_little_endian") {
                options.ply_format = t::io::PlyFormat::BinaryLittleEndian;
            } else if (ply_format == "binary_big_endian") {
                options.ply_format = t::io::PlyFormat::BinaryBigEndian;
            } else if (ply_format == "ascii") {
                options.ply_format = t::io::PlyFormat::Ascii;
            } else {
                core::ThrowError(
                    "write_point_cloud: ply_format '{}' (binary_little_endian, "
                    "binary_big_endian or ascii)",
                    ply_format);
            }
            const std::string path = PathString(filename);
            py::gil_scoped_release release;
            t::io::WritePointCloud(path, cloud.cloud, options);
        },
        py::arg("filename"), py::arg("pointcloud"), py::arg("ply_format") = "binary_little_endian",
        "Writes the format the extension names (.ply, .compressed.ply, .splat, .spz, .sog, .glb, "
        ".gltf); the file appears complete or not at all.");
    m.def(
        "write_splat_pages",
        [](const std::filesystem::path& filename, const PyPointCloud& cloud,
           int64_t page_capacity) {
            cloud.cloud.ValidateGaussianSplat();
            const std::string path = PathString(filename);
            py::gil_scoped_release release;
            const t::geometry::SplatHierarchy hierarchy =
                t::geometry::BuildSplatHierarchy(cloud.cloud);
            t::io::WriteSplatPages(path, cloud.cloud, hierarchy, page_capacity);
        },
        py::arg("filename"), py::arg("pointcloud"), py::arg("page_capacity") = 65536,
        "Builds the level-of-detail hierarchy of a Gaussian splat cloud and writes it as a paged "
        "file (.gspages, as gs-convert --pages does) of page_capacity nodes a page, for "
        "OffscreenRenderer.scene.stream_splats. Raises Open3DError for a cloud without the "
        "Gaussian attributes or a capacity below 8.");
}

}  // namespace pybind
}  // namespace open3d
