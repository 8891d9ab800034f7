// open3d_gs.t.geometry.AxisAlignedBoundingBox and OrientedBoundingBox: Open3D's boxes over the
// library's (t/geometry/BoundingBox.h), for PointCloud.crop and bounds (docs/editing.md).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "Bindings.h"
#include "open3d/t/geometry/BoundingBox.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

using t::geometry::AxisAlignedBoundingBox;
using t::geometry::OrientedBoundingBox;

void BindBoundingBoxes(py::module_& m) {
    py::class_<AxisAlignedBoundingBox>(
        m, "AxisAlignedBoundingBox",
        "An axis-aligned box, as Open3D's: min_bound and max_bound, float64 (3,). Closed: a "
        "point on a face is inside")
        .def(py::init<const Eigen::Vector3d&, const Eigen::Vector3d&>(), py::arg("min_bound"),
             py::arg("max_bound"),
             "A box from its two corners; raises for a non-finite bound or min_bound above "
             "max_bound on an axis")
        .def_property(
            "min_bound", &AxisAlignedBoundingBox::GetMinBound,
            [](AxisAlignedBoundingBox& b, const Eigen::Vector3d& v) {
                b = AxisAlignedBoundingBox(v, b.GetMaxBound());
            },
            "The lowest corner")
        .def_property(
            "max_bound", &AxisAlignedBoundingBox::GetMaxBound,
            [](AxisAlignedBoundingBox& b, const Eigen::Vector3d& v) {
                b = AxisAlignedBoundingBox(b.GetMinBound(), v);
            },
            "The highest corner")
        .def("get_center", &AxisAlignedBoundingBox::GetCenter, "The middle of the box")
        .def("get_extent", &AxisAlignedBoundingBox::GetExtent, "The side lengths")
        .def(
            "volume",
            [](const AxisAlignedBoundingBox& b) {
                return b.IsEmpty() ? 0.0 : b.GetExtent().prod();
            },
            "The product of the side lengths")
        .def(
            "contains",
            [](const AxisAlignedBoundingBox& b, const Eigen::Vector3d& p) { return b.Contains(p); },
            py::arg("point"), "Whether the point is inside or on the box")
        .def(
            "__repr__",
            [](const AxisAlignedBoundingBox& b) {
                return fmt::format("AxisAlignedBoundingBox(min_bound=[{}], max_bound=[{}])",
                                   fmt::join(b.GetMinBound(), ", "),
                                   fmt::join(b.GetMaxBound(), ", "));
            },
            "The corners");

    py::class_<OrientedBoundingBox>(
        m, "OrientedBoundingBox",
        "A box of edge lengths extent along the columns of the rotation R, centred at center, "
        "as Open3D's. Closed: a point on a face is inside")
        .def(py::init<const Eigen::Vector3d&, const Eigen::Matrix3d&, const Eigen::Vector3d&>(),
             py::arg("center"), py::arg("R"), py::arg("extent"),
             "A box from its centre, rotation (3, 3) and edge lengths; raises for a non-finite "
             "value, a negative edge or an R that is not a rotation")
        .def_static("create_from_axis_aligned_bounding_box", &OrientedBoundingBox::FromAxisAligned,
                    py::arg("aabox"), "The axis-aligned box as an oriented one (R = I)")
        .def_property_readonly("center", &OrientedBoundingBox::GetCenter, "The centre")
        .def_property_readonly("R", &OrientedBoundingBox::GetRotation, "The rotation (3, 3)")
        .def_property_readonly("extent", &OrientedBoundingBox::GetExtent, "The edge lengths")
        .def(
            "contains",
            [](const OrientedBoundingBox& b, const Eigen::Vector3d& p) { return b.Contains(p); },
            py::arg("point"), "Whether the point is inside or on the box")
        .def(
            "__repr__",
            [](const OrientedBoundingBox& b) {
                return fmt::format("OrientedBoundingBox(center=[{}], extent=[{}])",
                                   fmt::join(b.GetCenter(), ", "), fmt::join(b.GetExtent(), ", "));
            },
            "The centre and edge lengths");
}

}  // namespace pybind
}  // namespace open3d
