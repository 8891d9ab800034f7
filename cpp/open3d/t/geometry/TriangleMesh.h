// A small triangle mesh with named per-vertex attributes, for meshes drawn beside Gaussian
// splats. Front faces wind counter-clockwise when seen from outside (Open3D, Filament).
#pragma once

#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

#include "open3d/core/Tensor.h"

namespace open3d {
namespace t {
namespace geometry {

/// Vertex attribute names with a fixed meaning. Shapes: positions [N, 3] Float32 (required
/// for a non-empty mesh); normals [N, 3] Float32; colors [N, 3] Float32 in [0, 1].
/// Any other attribute needs N rows.
namespace mesh_attr {
inline constexpr const char* kPositions = "positions";
inline constexpr const char* kNormals = "normals";
inline constexpr const char* kColors = "colors";
}  // namespace mesh_attr

class TriangleMesh {
public:
    /// Triangle indices live in a std::vector of Eigen::Vector3i, not a core::Tensor:
    /// core::Dtype has only Float32, UInt8 and UInt16. UInt16 would cap meshes at 65,536
    /// vertices and Float32 indexes exactly only up to 2^24, so neither is an index type;
    /// adding Int32 to core is a separate change. Move to an Int32 tensor once core has one.
    using TriangleIndices = std::vector<Eigen::Vector3i>;

    TriangleMesh() = default;
    /// positions: [N, 3] Float32. triangles: indices into positions, counter-clockwise seen
    /// from the front. Indices are checked by Validate(), not here.
    TriangleMesh(core::Tensor positions, TriangleIndices triangles);

    int64_t NumVertices() const;
    int64_t NumTriangles() const { return static_cast<int64_t>(triangles_.size()); }
    /// True when the mesh has no vertices.
    bool IsEmpty() const { return NumVertices() == 0; }

    bool HasVertexPositions() const { return HasVertexAttr(mesh_attr::kPositions); }
    bool HasVertexNormals() const { return HasVertexAttr(mesh_attr::kNormals); }
    bool HasVertexColors() const { return HasVertexAttr(mesh_attr::kColors); }
    bool HasTriangleIndices() const { return !triangles_.empty(); }

    const core::Tensor& GetVertexPositions() const { return GetVertexAttr(mesh_attr::kPositions); }
    void SetVertexPositions(core::Tensor positions) {
        SetVertexAttr(mesh_attr::kPositions, std::move(positions));
    }
    const core::Tensor& GetVertexNormals() const { return GetVertexAttr(mesh_attr::kNormals); }
    void SetVertexNormals(core::Tensor normals) {
        SetVertexAttr(mesh_attr::kNormals, std::move(normals));
    }
    const core::Tensor& GetVertexColors() const { return GetVertexAttr(mesh_attr::kColors); }
    void SetVertexColors(core::Tensor colors) {
        SetVertexAttr(mesh_attr::kColors, std::move(colors));
    }

    bool HasVertexAttr(const std::string& name) const { return vertex_attrs_.count(name) > 0; }
    /// Throws Open3DError when the attribute is missing.
    const core::Tensor& GetVertexAttr(const std::string& name) const;
    /// Writable access; a caller that changes the shape or dtype is caught by Validate().
    core::Tensor& GetVertexAttr(const std::string& name);
    /// positions, normals and colors must be Float32 [N, 3]; every attribute needs as many
    /// rows as positions (checked against positions once they exist). Throws Open3DError.
    void SetVertexAttr(const std::string& name, core::Tensor value);
    void RemoveVertexAttr(const std::string& name) { vertex_attrs_.erase(name); }
    std::vector<std::string> GetVertexAttrNames() const;

    const TriangleIndices& GetTriangleIndices() const { return triangles_; }
    void SetTriangleIndices(TriangleIndices triangles) { triangles_ = std::move(triangles); }

    /// Throws Open3DError naming the first problem: an attribute with the wrong dtype, shape
    /// or row count, a triangle index outside [0, N), a non-finite position or normal, or a
    /// color outside [0, 1]. An empty mesh is valid.
    void Validate() const;

    /// Component-wise min / max of positions; zero for a mesh without vertices.
    Eigen::Vector3d GetMinBound() const;
    Eigen::Vector3d GetMaxBound() const;
    /// Mean of positions (Open3D's convention); zero for a mesh without vertices.
    Eigen::Vector3d GetCenter() const;
    /// Sum of triangle areas. Validates first.
    double GetSurfaceArea() const;

    // Geometric transforms (TriangleMeshTransform.cpp). Each checks its arguments and the
    // attribute shapes before changing anything, so a thrown error leaves the mesh as it was.
    // Normals follow with the inverse transpose and are renormalised; a transform with
    // det < 0 (a mirror) swaps two indices of every triangle so that front faces stay
    // counter-clockwise from outside. Colors and other attributes are unchanged.

    /// Moves positions by t (relative) or so that their mean lands on t (relative = false).
    TriangleMesh& Translate(const Eigen::Vector3d& translation, bool relative = true);
    /// p' = s (p - center) + center. A negative s mirrors (normals and winding flip); s = 0
    /// throws when the mesh has normals (they would be undefined).
    TriangleMesh& Scale(double scale, const Eigen::Vector3d& center);
    /// Orthonormal R about center; throws for any other matrix (use Transform for those).
    TriangleMesh& Rotate(const Eigen::Matrix3d& R, const Eigen::Vector3d& center);
    /// Affine 4x4 (last row 0 0 0 1). A singular linear part throws when the mesh has normals.
    TriangleMesh& Transform(const Eigen::Matrix4d& transformation);

    /// Area-weighted vertex normals: each vertex gets the normalised sum of the cross
    /// products (b - a) x (c - a) of its triangles, i.e. face normals weighted by twice the
    /// area. Vertices without a non-degenerate triangle get (0, 0, 0). Validates first.
    TriangleMesh& ComputeVertexNormals();
    /// Sets every vertex color to rgb; each channel must be in [0, 1]. Needs positions.
    TriangleMesh& PaintUniformColor(const Eigen::Vector3d& rgb);

    // Factories (TriangleMeshFactory.cpp).

    /// UV sphere centred at the origin, as Open3D's: poles at (0, 0, +-radius) and
    /// resolution - 1 rings of 2 * resolution vertices, so 2 * resolution * (resolution - 1)
    /// + 2 vertices and 4 * resolution * (resolution - 1) triangles, counter-clockwise seen
    /// from outside, with exact unit normals. Needs radius > 0 and resolution >= 2.
    static TriangleMesh CreateSphere(double radius = 1.0, int resolution = 20);
    /// Axis-aligned box from the origin to (width, height, depth), as Open3D's. It has 24
    /// vertices (4 per face) so that every face carries its own flat normal, which is what
    /// a renderer needs for sharp edges; 12 triangles, counter-clockwise seen from outside.
    static TriangleMesh CreateBox(double width = 1.0, double height = 1.0, double depth = 1.0);

    bool operator==(const TriangleMesh& other) const {
        return vertex_attrs_ == other.vertex_attrs_ && triangles_ == other.triangles_;
    }

private:
    // Dtype, shape and row count of every vertex attribute.
    void ValidateAttributeShapes() const;
    // Every triangle index in [0, NumVertices()).
    void ValidateTriangleIndices() const;
    // p' = A p + t, normals by A^{-T}, winding swapped when det(A) < 0. Validates first.
    void ApplyAffine(const Eigen::Matrix3d& A, const Eigen::Vector3d& t);

    std::map<std::string, core::Tensor> vertex_attrs_;
    TriangleIndices triangles_;  // [M] counter-clockwise from the front
};

}  // namespace geometry
}  // namespace t
}  // namespace open3d
