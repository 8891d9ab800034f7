// t.geometry: PointCloud with its attributes as numpy arrays (docs/python.md "Arrays").
#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <fmt/format.h>

#include <map>
#include <memory>
#include <string>
#include <utility>

#include "Bindings.h"
#include "NumpyTensor.h"
#include "PyPointCloud.h"
#include "open3d/core/Exception.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

void PyPointCloud::RequireNoViews(const std::string& name, const char* action) const {
    const auto it = views.find(name);
    if (it != views.end() && it->second > 0) {
        core::ThrowError(
            "PointCloud: cannot {} attribute '{}' while {} numpy view(s) of it are alive (their "
            "memory would go); delete them or take .copy() first",
            action, name, it->second);
    }
}

namespace {

using Cloud = std::shared_ptr<PyPointCloud>;

// A view of one attribute; the capsule keeps the cloud alive and counts the view.
py::array AttributeView(const Cloud& cloud, const std::string& name) {
    core::Tensor& tensor = cloud->cloud.GetPointAttr(name);  // throws for a missing name
    struct Keeper {
        Cloud cloud;
        std::string name;
    };
    auto* keeper = new Keeper{cloud, name};
    ++cloud->views[name];
    py::capsule owner(keeper, [](void* p) {
        auto* k = static_cast<Keeper*>(p);
        --k->cloud->views[k->name];
        delete k;
    });
    return ViewOfTensor(tensor, owner);
}

// `pcd.point`: the attributes by name, as Open3D's TensorMap is reached from Python.
struct PointAttributes {
    Cloud cloud;
};

}  // namespace

void BindGeometry(py::module_& m) {
    py::class_<PointAttributes>(m, "PointAttributes",
                                "The per-point attributes of a PointCloud by name: reading one "
                                "gives a numpy view of the cloud's memory (no copy), assigning "
                                "one copies the array in.")
        .def("__getitem__", [](const PointAttributes& a,
                               const std::string& name) { return AttributeView(a.cloud, name); })
        .def("__setitem__",
             [](PointAttributes& a, const std::string& name, const py::array& value) {
                 a.cloud->RequireNoViews(name, "replace");
                 a.cloud->cloud.SetPointAttr(name,
                                             TensorFromArray(value, "attribute '" + name + "'"));
             })
        .def("__delitem__",
             [](PointAttributes& a, const std::string& name) {
                 if (!a.cloud->cloud.HasPointAttr(name)) throw py::key_error(name);
                 a.cloud->RequireNoViews(name, "remove");
                 a.cloud->cloud.RemovePointAttr(name);
             })
        .def("__contains__",
             [](const PointAttributes& a, const std::string& name) {
                 return a.cloud->cloud.HasPointAttr(name);
             })
        .def("__len__",
             [](const PointAttributes& a) { return a.cloud->cloud.GetPointAttrNames().size(); })
        .def("keys", [](const PointAttributes& a) { return a.cloud->cloud.GetPointAttrNames(); })
        .def("__getattr__",
             [](const PointAttributes& a, const std::string& name) -> py::array {
                 if (!a.cloud->cloud.HasPointAttr(name)) {
                     throw py::attribute_error(
                         fmt::format("PointCloud has no attribute '{}'", name));
                 }
                 return AttributeView(a.cloud, name);
             })
        .def("__repr__", [](const PointAttributes& a) {
            return fmt::format("PointAttributes({})",
                               fmt::join(a.cloud->cloud.GetPointAttrNames(), ", "));
        });

    py::class_<PyPointCloud, Cloud>(
        m, "PointCloud",
        "A point cloud whose points may carry the 3DGS attributes: positions [N, 3], scale [N, "
        "3] (linear), rot [N, 4] (w, x, y, z), opacity [N, 1] (logit), f_dc [N, 3], f_rest "
        "[N, Nc, 3]; all float32.")
        .def(py::init([] { return std::make_shared<PyPointCloud>(); }))
        .def(py::init([](const py::array& positions) {
                 auto cloud = std::make_shared<PyPointCloud>();
                 cloud->cloud.SetPointPositions(TensorFromArray(positions, "positions"));
                 return cloud;
             }),
             py::arg("positions"))
        .def_property_readonly(
            "point", [](const Cloud& c) { return PointAttributes{c}; },
            "The attributes by name (pcd.point['scale'] or pcd.point.scale)")
        .def("__len__", [](const PyPointCloud& c) { return c.cloud.NumPoints(); })
        .def("num_points", [](const PyPointCloud& c) { return c.cloud.NumPoints(); })
        .def("is_gaussian_splat", [](const PyPointCloud& c) { return c.cloud.IsGaussianSplat(); })
        .def(
            "get_sh_degree",
            [](const PyPointCloud& c) { return c.cloud.GaussianSplatGetSHOrder(); },
            "SH degree 0..3; raises for a cloud without the Gaussian attributes")
        .def(
            "validate", [](const PyPointCloud& c) { c.cloud.ValidateGaussianSplat(); },
            "Raises naming the first attribute whose dtype or shape is wrong")
        .def("get_center", [](const PyPointCloud& c) { return c.cloud.GetCenter(); })
        // The transforms write the attributes in place: views stay valid and see the result.
        .def(
            "translate",
            [](const Cloud& c, const Eigen::Vector3d& t, bool relative) {
                c->cloud.Translate(t, relative);
                return c;
            },
            py::arg("translation"), py::arg("relative") = true)
        .def(
            "rotate",
            [](const Cloud& c, const Eigen::Matrix3d& R, const Eigen::Vector3d& center) {
                c->cloud.Rotate(R, center);
                return c;
            },
            py::arg("R"), py::arg("center"),
            "Proper rotation about center: positions, rot and the SH coefficients follow")
        .def(
            "scale",
            [](const Cloud& c, double s, const Eigen::Vector3d& center) {
                c->cloud.Scale(s, center);
                return c;
            },
            py::arg("scale"), py::arg("center"))
        .def(
            "clone",
            [](const PyPointCloud& c) {
                auto copy = std::make_shared<PyPointCloud>();
                copy->cloud = c.cloud;
                return copy;
            },
            "A deep copy")
        .def("__repr__", [](const PyPointCloud& c) {
            return fmt::format("PointCloud with {} points ({})", c.cloud.NumPoints(),
                               fmt::join(c.cloud.GetPointAttrNames(), ", "));
        });
}

}  // namespace pybind
}  // namespace open3d
