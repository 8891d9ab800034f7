// t.geometry: PointCloud with its attributes as numpy arrays (docs/python.md "Arrays").
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <fmt/format.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "Bindings.h"
#include "NumpyTensor.h"
#include "PointCloudOps.h"
#include "PyPointCloud.h"
#include "open3d/core/Exception.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/Picking.h"
#include "open3d/visualization/rendering/gaussian_splat/cpu/ViewSelection.h"

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

// Assigning an attribute: a copy in (numpy arrays of any real dtype, lists), opacity (N,)
// taken as (N, 1), non-finite values refused unless asked for.
void SetAttribute(const Cloud& cloud, const std::string& name, const py::handle& value,
                  bool allow_non_finite) {
    cloud->RequireNoViews(name, "replace");
    const std::string what = "attribute '" + name + "'";
    py::array array = ArrayForTensor(value, what);
    if (name == t::geometry::gs_attr::kOpacity && array.ndim() == 1) {
        array = array.attr("reshape")(-1, 1);  // 3DGS code keeps opacity as (N,) as often
    }
    cloud->cloud.SetPointAttr(name, TensorFromArray(array, what, allow_non_finite));
}

std::shared_ptr<PyPointCloud> Wrap(t::geometry::PointCloud cloud) {
    auto out = std::make_shared<PyPointCloud>();
    out->cloud = std::move(cloud);
    return out;
}

// Row indices from a sequence or array of integers, each in [0, n).
std::vector<int64_t> Indices(const py::handle& value, int64_t n) {
    const py::module_ np = py::module_::import("numpy");
    const py::array array = np.attr("asarray")(value);
    const char kind = array.dtype().kind();
    if (array.ndim() != 1 || (array.size() > 0 && kind != 'i' && kind != 'u')) {
        core::ThrowError("select_by_index: indices must be a 1-D sequence of integers, got {} {}",
                         std::string(py::str(array.dtype())),
                         std::string(py::str(array.attr("shape"))));
    }
    const py::array_t<int64_t> wide = np.attr("asarray")(array, np.attr("int64"));
    std::vector<int64_t> indices(wide.data(), wide.data() + wide.size());
    for (int64_t i : indices) {
        if (i < 0 || i >= n) {
            core::ThrowError("select_by_index: index {} is out of range for {} points", i, n);
        }
    }
    return indices;
}

}  // namespace

void BindGeometry(py::module_& m) {
    py::class_<PointAttributes>(m, "PointAttributes",
                                "The per-point attributes of a PointCloud by name: reading one "
                                "gives a numpy view of the cloud's memory (no copy), assigning "
                                "one copies the array in (converted to float32 unless it is "
                                "float32, uint8 or uint16; NaN and infinity refused).")
        .def(
            "__getitem__",
            [](const PointAttributes& a, const std::string& name) {
                return AttributeView(a.cloud, name);
            },
            py::arg("name"),
            "A numpy view of the attribute (no copy); KeyError-like Open3DError when absent")
        .def(
            "__setitem__",
            [](PointAttributes& a, const std::string& name, const py::object& value) {
                SetAttribute(a.cloud, name, value, false);
            },
            py::arg("name"), py::arg("value"),
            "Copies an array (or list) in as the attribute; see PointCloud.set_point_attr")
        .def(
            "__delitem__",
            [](PointAttributes& a, const std::string& name) {
                if (!a.cloud->cloud.HasPointAttr(name)) throw py::key_error(name);
                a.cloud->RequireNoViews(name, "remove");
                a.cloud->cloud.RemovePointAttr(name);
            },
            py::arg("name"), "Removes the attribute (refused while views of it are alive)")
        .def(
            "__contains__",
            [](const PointAttributes& a, const std::string& name) {
                return a.cloud->cloud.HasPointAttr(name);
            },
            py::arg("name"), "Whether the cloud has the attribute")
        .def(
            "__len__",
            [](const PointAttributes& a) { return a.cloud->cloud.GetPointAttrNames().size(); },
            "The number of attributes")
        .def(
            "keys", [](const PointAttributes& a) { return a.cloud->cloud.GetPointAttrNames(); },
            "The attribute names, sorted")
        .def(
            "__iter__",
            [](const PointAttributes& a) {
                return py::iter(py::cast(a.cloud->cloud.GetPointAttrNames()));
            },
            "The attribute names, sorted (for name in pcd.point, as over a dict)")
        .def(
            "__getattr__",
            [](const PointAttributes& a, const std::string& name) -> py::array {
                if (!a.cloud->cloud.HasPointAttr(name)) {
                    throw py::attribute_error(
                        fmt::format("PointCloud has no attribute '{}'", name));
                }
                return AttributeView(a.cloud, name);
            },
            py::arg("name"), "pcd.point.scale: the same view as pcd.point['scale']")
        .def(
            "__setattr__",
            [](PointAttributes& a, const std::string& name, const py::object& value) {
                SetAttribute(a.cloud, name, value, false);
            },
            py::arg("name"), py::arg("value"),
            "pcd.point.scale = array, as Open3D's TensorMap: the same as pcd.point['scale'] = "
            "array")
        .def(
            "__repr__",
            [](const PointAttributes& a) {
                return fmt::format("PointAttributes({})",
                                   fmt::join(a.cloud->cloud.GetPointAttrNames(), ", "));
            },
            "The attribute names");

    py::class_<PyPointCloud, Cloud>(
        m, "PointCloud",
        "A point cloud whose points may carry the 3DGS attributes: positions [N, 3], scale [N, "
        "3] (linear), rot [N, 4] (w, x, y, z), opacity [N, 1] (logit), f_dc [N, 3], f_rest "
        "[N, Nc, 3]; all float32. PointCloud(positions), PointCloud({name: array, ...}) or "
        "PointCloud(); arrays and lists of any real dtype are copied in as float32.")
        .def(py::init([] { return std::make_shared<PyPointCloud>(); }), "An empty cloud")
        .def(py::init([](const py::dict& attributes) {
                 auto cloud = std::make_shared<PyPointCloud>();
                 // Positions first: the other attributes' rows are checked against them.
                 if (attributes.contains("positions")) {
                     SetAttribute(cloud, "positions", attributes["positions"], false);
                 }
                 for (const auto& [key, value] : attributes) {
                     const std::string name = py::str(key);
                     if (name != "positions") SetAttribute(cloud, name, value, false);
                 }
                 return cloud;
             }),
             py::arg("map_keys_to_tensors"),
             "A cloud of the attributes of a dict {name: array}, as Open3D's")
        .def(py::init([](const py::object& positions) {
                 auto cloud = std::make_shared<PyPointCloud>();
                 SetAttribute(cloud, "positions", positions, false);
                 return cloud;
             }),
             py::arg("positions"), "A cloud of positions [N, 3] (an array or a list)")
        .def_property_readonly(
            "point", [](const Cloud& c) { return PointAttributes{c}; },
            "The attributes by name (pcd.point['scale'] or pcd.point.scale)")
        .def(
            "set_point_attr",
            [](const Cloud& c, const std::string& name, const py::object& value,
               bool allow_non_finite) { SetAttribute(c, name, value, allow_non_finite); },
            py::arg("name"), py::arg("value"), py::kw_only(), py::arg("allow_non_finite") = false,
            "pcd.point[name] = value with the opt-out: float32, uint8 and uint16 arrays are "
            "copied as they are, other real dtypes (float64, float16, integers, lists) "
            "converted to float32; opacity (N,) is taken as (N, 1). NaN and infinity are "
            "refused naming the attribute and the first row holding one, unless "
            "allow_non_finite (the renderer's sort and blend do not survive them)")
        .def(
            "__len__", [](const PyPointCloud& c) { return c.cloud.NumPoints(); },
            "The number of points")
        .def(
            "num_points", [](const PyPointCloud& c) { return c.cloud.NumPoints(); },
            "The number of points")
        .def(
            "is_empty", [](const PyPointCloud& c) { return c.cloud.NumPoints() == 0; },
            "True for a cloud without points (Open3D's)")
        .def(
            "is_gaussian_splat", [](const PyPointCloud& c) { return c.cloud.IsGaussianSplat(); },
            "True when scale, rot, opacity and f_dc are there with valid shapes")
        .def(
            "get_sh_degree",
            [](const PyPointCloud& c) { return c.cloud.GaussianSplatGetSHOrder(); },
            "SH degree 0..3; raises for a cloud without the Gaussian attributes")
        .def(
            "validate", [](const PyPointCloud& c) { c.cloud.ValidateGaussianSplat(); },
            "Raises naming the first attribute whose dtype or shape is wrong")
        .def(
            "get_center", [](const PyPointCloud& c) { return c.cloud.GetCenter(); },
            "The mean of the positions, float64 (3,); zero for an empty cloud")
        .def(
            "get_min_bound", [](const PyPointCloud& c) { return Bound(c.cloud, false); },
            "The per-axis minimum of the positions, float64 (3,); zero for an empty cloud")
        .def(
            "get_max_bound", [](const PyPointCloud& c) { return Bound(c.cloud, true); },
            "The per-axis maximum of the positions, float64 (3,); zero for an empty cloud")
        .def(
            "get_axis_aligned_bounding_box",
            [](const PyPointCloud& c) {
                // An empty cloud's box has zero corners, as get_min_bound says.
                const t::geometry::AxisAlignedBoundingBox box = c.cloud.GetAxisAlignedBoundingBox();
                return t::geometry::AxisAlignedBoundingBox(box.GetMinBound(), box.GetMaxBound());
            },
            "The box of the positions (get_min_bound to get_max_bound)")
        .def(
            "crop",
            [](const PyPointCloud& c, const t::geometry::AxisAlignedBoundingBox& box, bool invert) {
                return Wrap(c.cloud.Crop(box, invert));
            },
            py::arg("aabb"), py::arg("invert") = false,
            "A new cloud of the points (splats by their centres) inside the box, every attribute "
            "copied bit for bit; with invert, of the points outside")
        .def(
            "crop",
            [](const PyPointCloud& c, const t::geometry::OrientedBoundingBox& box, bool invert) {
                return Wrap(c.cloud.Crop(box, invert));
            },
            py::arg("obb"), py::arg("invert") = false,
            "A new cloud of the points (splats by their centres) inside the oriented box; with "
            "invert, of the points outside")
        .def(
            "remove_by_index",
            [](const PyPointCloud& c, const py::object& indices) {
                return Wrap(c.cloud.RemoveByIndex(Indices(indices, c.cloud.NumPoints())));
            },
            py::arg("indices"),
            "A new cloud without the points at indices (select_by_index with invert)")
        .def(
            "pick",
            [](const PyPointCloud& c, const py::object& camera, int x, int y) {
                c.cloud.ValidateGaussianSplat();
                const visualization::rendering::cpu::PickResult pick =
                    visualization::rendering::cpu::PickPixel(
                        c.cloud, camera.cast<camera::PinholeCamera>(),
                        visualization::rendering::RenderConfig(), x, y);
                py::dict out;
                out["hit"] = pick.hit;
                out["splat"] = pick.splat;
                out["weight"] = pick.weight;
                out["alpha"] = pick.alpha;
                out["expected_depth"] = pick.expected_depth;
                out["median_depth"] = pick.median_depth;
                out["point"] = pick.point;
                return out;
            },
            py::arg("camera"), py::arg("x"), py::arg("y"),
            "Picks pixel (x, y) of the camera's (a PinholeCamera) view, as the CPU reference "
            "composites it: a dict with hit, splat (the index of the splat of largest blend "
            "weight there, -1 for none), weight, alpha (1 - T), expected_depth and median_depth "
            "(view z, as the depth images hold them) and point (the world point on the pixel's "
            "ray at the expected depth)")
        .def(
            "select_in_view",
            // The camera as an object: PinholeCamera is bound after this module, so a typed
            // argument would leave a C++ name in the signature (and the stubs).
            [](const PyPointCloud& c, const py::object& camera,
               const std::vector<Eigen::Vector2d>& polygon, bool include_occluded) {
                c.cloud.ValidateGaussianSplat();
                const std::vector<int64_t> rows = visualization::rendering::cpu::SelectSplatsInView(
                    c.cloud, camera.cast<camera::PinholeCamera>(),
                    visualization::rendering::RenderConfig(), polygon, include_occluded);
                return py::array_t<int64_t>(py::ssize_t(rows.size()), rows.data());
            },
            py::arg("camera"), py::arg("polygon"), py::arg("include_occluded") = false,
            "Indices (int64, ascending) of the splats whose centre the camera (a "
            "PinholeCamera) projects inside "
            "polygon (pixel (x, y) pairs, at least 3: a rectangle's corners or a lasso) and "
            "that the view shows there (a blend weight of at least 1/255 at a pixel inside, "
            "the CPU reference's rules); include_occluded also takes what lies behind and what "
            "is too faint to show. Use with select_by_index or remove_by_index")
        // The transforms write the attributes in place: views stay valid and see the result.
        .def(
            "translate",
            [](const Cloud& c, const Eigen::Vector3d& t, bool relative) {
                c->cloud.Translate(t, relative);
                return c;
            },
            py::arg("translation"), py::arg("relative") = true,
            "Moves the positions by translation, or (relative=False) so that their mean lands "
            "on it; returns the cloud")
        .def(
            "rotate",
            [](const Cloud& c, const Eigen::Matrix3d& R,
               const std::optional<Eigen::Vector3d>& center) {
                c->cloud.Rotate(R, center.value_or(c->cloud.GetCenter()));
                return c;
            },
            py::arg("R"), py::arg("center") = py::none(),
            "Proper rotation about center (default: the cloud's centre, get_center(), as "
            "Open3D's Geometry3D.rotate(R) does): positions, rot and the SH coefficients "
            "follow; returns the cloud. A reflection or a scaled matrix is refused")
        .def(
            "scale",
            [](const Cloud& c, double s, const Eigen::Vector3d& center) {
                c->cloud.Scale(s, center);
                return c;
            },
            py::arg("scale"), py::arg("center"),
            "Uniform scale about center: positions and the splats' scales follow (a negative "
            "factor inverts through center, the SH parity with it); returns the cloud")
        .def(
            "transform",
            [](const Cloud& c, const Eigen::Matrix4d& transformation) {
                TransformCloud(c->cloud, transformation);
                return c;
            },
            py::arg("transformation"),
            "Applies a 4x4 matrix [A t; 0 0 0 1] in place and returns the cloud. With the "
            "Gaussian attributes A must be a rotation times a uniform scale (s R, s < 0 an "
            "inversion): the splats are scaled, rotated (rot and SH follow) and translated, "
            "so they keep their look; a shear or a non-uniform scale is refused. Without "
            "them any affine matrix moves the positions")
        .def(
            "select_by_index",
            [](const PyPointCloud& c, const py::object& indices, bool invert) {
                return Wrap(c.cloud.SelectByIndex(Indices(indices, c.cloud.NumPoints()), invert));
            },
            py::arg("indices"), py::arg("invert") = false,
            "A new cloud of the points at indices (in that order), or with invert of every "
            "other point (in cloud order); every attribute follows")
        .def(
            "select_by_mask",
            [](const PyPointCloud& c, const py::object& mask, bool invert) {
                const py::array array = py::module_::import("numpy").attr("asarray")(mask);
                if (array.dtype().kind() != 'b' || array.ndim() != 1 ||
                    array.size() != c.cloud.NumPoints()) {
                    core::ThrowError(
                        "select_by_mask: the mask must be a 1-D bool array of {} entries (one "
                        "a point), got {} {}",
                        c.cloud.NumPoints(), std::string(py::str(array.dtype())),
                        std::string(py::str(array.attr("shape"))));
                }
                const py::array_t<uint8_t> flags = array.attr("view")("uint8");
                const std::vector<bool> keep(flags.data(), flags.data() + flags.size());
                return Wrap(c.cloud.SelectByMask(keep, invert));
            },
            py::arg("boolean_mask"), py::arg("invert") = false,
            "A new cloud of the points whose mask entry is True (False with invert)")
        .def(
            "append",
            [](const PyPointCloud& a, const PyPointCloud& b) {
                return Wrap(Append(a.cloud, b.cloud));
            },
            py::arg("other"),
            "A new cloud of this cloud's points then other's. Gaussian splat clouds of "
            "different SH degrees merge at the higher one (zero coefficients for the bands a "
            "cloud lacks, as the renderer's scene merges); other attributes must be in both")
        .def(
            "__add__",
            [](const PyPointCloud& a, const PyPointCloud& b) {
                return Wrap(Append(a.cloud, b.cloud));
            },
            py::arg("other"), "a + b: a.append(b)")
        .def(
            "clone", [](const PyPointCloud& c) { return Wrap(c.cloud); }, "A deep copy")
        .def(
            "__repr__",
            [](const PyPointCloud& c) {
                return fmt::format("PointCloud with {} points ({})", c.cloud.NumPoints(),
                                   fmt::join(c.cloud.GetPointAttrNames(), ", "));
            },
            "The point count and the attribute names");
}

}  // namespace pybind
}  // namespace open3d
