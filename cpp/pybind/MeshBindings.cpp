// t.geometry.TriangleMesh (copied in and out: meshes are small next to splat scenes) and
// visualization.rendering.MaterialRecord.
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <fmt/format.h>

#include <cstring>

#include "Bindings.h"
#include "NumpyTensor.h"
#include "PyMaterial.h"
#include "open3d/core/Exception.h"
#include "open3d/t/geometry/TriangleMesh.h"
#include "open3d/visualization/rendering/filament/MaterialRecord.h"

namespace py = pybind11;

namespace open3d {
namespace pybind {

namespace {

py::array CopyOfTensor(const core::Tensor& tensor) {
    py::array_t<float> out({py::ssize_t(tensor.GetShape(0)), py::ssize_t(tensor.GetShape(1))});
    std::memcpy(out.mutable_data(), tensor.Data<float>(), size_t(tensor.NumBytes()));
    return out;
}

}  // namespace

void BindMesh(py::module_& m) {
    using t::geometry::TriangleMesh;
    py::class_<TriangleMesh>(
        m, "TriangleMesh",
        "Vertices [N, 3] float32 and triangles [M, 3] (counter-clockwise "
        "seen from the front); drawn by Filament (OffscreenRenderer(meshes=True))")
        .def(py::init([](const py::array& vertices, const py::array_t<int64_t>& triangles) {
                 if (triangles.ndim() != 2 || triangles.shape(1) != 3) {
                     core::ThrowError("TriangleMesh: triangles must have shape (M, 3)");
                 }
                 TriangleMesh::TriangleIndices indices(triangles.shape(0));
                 const auto t = triangles.unchecked<2>();
                 for (py::ssize_t i = 0; i < triangles.shape(0); ++i) {
                     indices[i] = Eigen::Vector3i(int(t(i, 0)), int(t(i, 1)), int(t(i, 2)));
                 }
                 TriangleMesh mesh(TensorFromArray(vertices, "vertices"), std::move(indices));
                 mesh.Validate();
                 return mesh;
             }),
             py::arg("vertices"), py::arg("triangles"),
             "A mesh of vertices [N, 3] (any real dtype, copied as float32) and triangles [M, "
             "3] of vertex indices")
        .def_static("create_sphere", &TriangleMesh::CreateSphere, py::arg("radius") = 1.0,
                    py::arg("resolution") = 20, "A UV sphere about the origin")
        .def_static("create_box", &TriangleMesh::CreateBox, py::arg("width") = 1.0,
                    py::arg("height") = 1.0, py::arg("depth") = 1.0,
                    "A box with one corner at the origin and the opposite one at (width, "
                    "height, depth)")
        .def("num_vertices", &TriangleMesh::NumVertices, "The number of vertices")
        .def("num_triangles", &TriangleMesh::NumTriangles, "The number of triangles")
        .def_property_readonly(
            "vertices",
            [](const TriangleMesh& mesh) { return CopyOfTensor(mesh.GetVertexPositions()); },
            "A copy of the vertex positions")
        .def(
            "set_vertex_colors",
            [](TriangleMesh& mesh, const py::array& colors) {
                mesh.SetVertexColors(TensorFromArray(colors, "vertex colors"));
                mesh.Validate();
            },
            py::arg("colors"), "Linear RGB [N, 3] float32 in 0..1")
        .def(
            "translate",
            [](TriangleMesh& mesh, const Eigen::Vector3d& t) -> TriangleMesh& {
                return mesh.Translate(t);
            },
            py::arg("translation"), py::return_value_policy::reference_internal,
            "Moves the vertices by translation; returns the mesh")
        .def(
            "__repr__",
            [](const TriangleMesh& mesh) {
                return fmt::format("TriangleMesh with {} vertices and {} triangles",
                                   mesh.NumVertices(), mesh.NumTriangles());
            },
            "The vertex and triangle counts");
}

void BindMaterial(py::module_& m) {
    using visualization::rendering::MaterialRecord;
    py::class_<PyMaterialRecord>(
        m, "MaterialRecord",
        "How a geometry is drawn, as Open3D's: shader 'defaultUnlit', 'defaultLit' (meshes, "
        "points) or 'gaussianSplat'. While shader is left unset the geometry is drawn its own "
        "way: a Gaussian splat cloud as splats (what a renderer without meshes draws), a plain "
        "cloud as points, a mesh unlit; reading it gives Open3D's default, 'defaultUnlit'.")
        .def(py::init<>(), "Open3D's defaults; the shader left to the geometry (see the class)")
        .def_property(
            "shader", [](const PyMaterialRecord& r) { return r.shader; },
            [](PyMaterialRecord& r, const std::string& shader) {
                r.shader = shader;
                r.shader_set = true;
            },
            "'defaultUnlit', 'defaultLit' or 'gaussianSplat'")
        .def_readwrite("base_color", &PyMaterialRecord::base_color,
                       "Linear RGBA multiplied with the vertex colours")
        .def_readwrite("point_size", &PyMaterialRecord::point_size,
                       "Point clouds drawn as points: the side of each point in pixels")
        .def_readwrite("gaussian_splat_sh_degree", &PyMaterialRecord::gaussian_splat_sh_degree,
                       "'gaussianSplat': the highest SH band used (0..3)")
        .def_readwrite("gaussian_splat_antialias", &PyMaterialRecord::gaussian_splat_antialias,
                       "'gaussianSplat': Mip-Splatting's antialias, for clouds trained with it")
        .def(
            "__repr__",
            [](const PyMaterialRecord& r) {
                return fmt::format("MaterialRecord(shader='{}'{})", r.shader,
                                   r.shader_set ? "" : ", unset: the geometry's own way");
            },
            "The shader, and whether it was set");
}

}  // namespace pybind
}  // namespace open3d
