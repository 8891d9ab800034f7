// A point cloud with named per-point attributes; with the Gaussian attributes present
// it is a 3D Gaussian Splatting scene.
#pragma once

#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

#include "open3d/core/Tensor.h"
#include "open3d/t/geometry/BoundingBox.h"

namespace open3d {
namespace t {
namespace geometry {

/// Attribute names of a Gaussian splat cloud (Open3D's names).
/// Shapes: positions [N,3]; scale [N,3] linear; rot [N,4] unit quaternion (w,x,y,z);
/// opacity [N,1] logit (sigmoid applied when packing for the GPU); f_dc [N,3];
/// f_rest [N,Nc,3] with Nc = (degree+1)^2 - 1, degree 1..3 (absent for degree 0).
namespace gs_attr {
inline constexpr const char* kPositions = "positions";
inline constexpr const char* kScale = "scale";
inline constexpr const char* kRot = "rot";
inline constexpr const char* kOpacity = "opacity";
inline constexpr const char* kFDc = "f_dc";
inline constexpr const char* kFRest = "f_rest";
}  // namespace gs_attr

/// Number of f_rest coefficients per channel for an SH degree: (degree+1)^2 - 1.
inline int NumSHRestCoeffs(int degree) { return (degree + 1) * (degree + 1) - 1; }

/// Read-only pointers to the attributes of a valid Gaussian splat cloud, looked up once:
/// loops over splats index these instead of looking attributes up by name.
struct GaussianSplatArrays {
    int64_t num_points = 0;
    int sh_degree = 0;                 ///< 0..3
    int num_rest = 0;                  ///< Nc = (degree + 1)^2 - 1 coefficients per channel
    const float* positions = nullptr;  // [N, 3]
    const float* scale = nullptr;      // [N, 3] linear
    const float* rot = nullptr;        // [N, 4] (w, x, y, z)
    const float* opacity = nullptr;    // [N, 1] logit
    const float* f_dc = nullptr;       // [N, 3]
    const float* f_rest = nullptr;     // [N, Nc, 3]; null at degree 0
};

class PointCloud {
public:
    PointCloud() = default;
    /// positions: [N, 3] Float32.
    explicit PointCloud(core::Tensor positions);

    int64_t NumPoints() const;
    bool IsEmpty() const { return NumPoints() == 0; }

    const core::Tensor& GetPointPositions() const { return GetPointAttr(gs_attr::kPositions); }
    void SetPointPositions(core::Tensor positions) {
        SetPointAttr(gs_attr::kPositions, std::move(positions));
    }

    bool HasPointAttr(const std::string& name) const { return attrs_.count(name) > 0; }
    /// Throws Open3DError when the attribute is missing.
    const core::Tensor& GetPointAttr(const std::string& name) const;
    core::Tensor& GetPointAttr(const std::string& name);
    /// The first dimension must equal NumPoints() unless the cloud has no positions yet.
    void SetPointAttr(const std::string& name, core::Tensor value);
    void RemovePointAttr(const std::string& name) { attrs_.erase(name); }
    std::vector<std::string> GetPointAttrNames() const;
    /// Bytes held by all attributes (what a copy of the cloud takes).
    int64_t NumBytes() const;

    /// True when scale, rot, opacity and f_dc exist (f_rest optional) with valid shapes.
    bool IsGaussianSplat() const;
    /// SH degree 0..3 from the f_rest shape. Throws if the cloud is not a valid splat cloud.
    int GaussianSplatGetSHOrder() const;
    /// Throws Open3DError naming the first attribute whose dtype or shape is wrong.
    void ValidateGaussianSplat() const;
    /// Validates (as ValidateGaussianSplat) and returns the attribute arrays. The pointers
    /// stay valid until an attribute is set or removed.
    GaussianSplatArrays GetGaussianSplatArrays() const;

    // Geometric transforms (PointCloudTransform.cpp). For splat clouds every Gaussian
    // attribute follows: see docs/transforms.md.

    /// Moves positions by t (relative) or so that their mean lands on t (relative = false).
    PointCloud& Translate(const Eigen::Vector3d& translation, bool relative = true);
    /// Proper rotation R (det +1, orthonormal) about center: positions rotate, rot is
    /// left-multiplied by q_R, f_rest is rotated band by band. Throws for any other matrix
    /// and leaves the cloud unchanged.
    PointCloud& Rotate(const Eigen::Matrix3d& R, const Eigen::Vector3d& center);
    /// Uniform scale s about center: scale *= |s|; s < 0 negates odd SH bands (parity).
    PointCloud& Scale(double scale, const Eigen::Vector3d& center);
    /// General 4x4 transform of positions only; warns for splat clouds (attributes unchanged).
    PointCloud& Transform(const Eigen::Matrix4d& transformation);
    /// Mean of positions (zero for an empty cloud).
    Eigen::Vector3d GetCenter() const;

    // Selection (PointCloudSelect.cpp, docs/editing.md): new clouds of some of the rows, every
    // attribute (Gaussian or not) copied bit for bit; the source is unchanged. Each throws
    // core::Open3DError before copying anything when an argument does not fit the cloud.

    /// The rows at `indices`, in that order (repeats kept); with invert, every row not
    /// among them, in cloud order (repeats ignored). Throws naming an index out of range.
    PointCloud SelectByIndex(const std::vector<int64_t>& indices, bool invert = false) const;
    /// The rows whose mask entry is true (false with invert); the mask has one entry a row.
    PointCloud SelectByMask(const std::vector<bool>& mask, bool invert = false) const;
    /// The points (splats by their centres) inside the closed box; with invert, the others.
    PointCloud Crop(const AxisAlignedBoundingBox& box, bool invert = false) const;
    PointCloud Crop(const OrientedBoundingBox& box, bool invert = false) const;
    /// Every row but `indices` (SelectByIndex with invert): Open3D's removal.
    PointCloud RemoveByIndex(const std::vector<int64_t>& indices) const {
        return SelectByIndex(indices, true);
    }
    /// The smallest axis-aligned box around the positions (empty for an empty cloud).
    AxisAlignedBoundingBox GetAxisAlignedBoundingBox() const;

    bool operator==(const PointCloud& other) const { return attrs_ == other.attrs_; }

private:
    std::map<std::string, core::Tensor> attrs_;
};

/// The rows of [0, n) that are not among `indices` (any order, repeats ignored), ascending:
/// SelectByIndex's inverted rows. Every index must lie in [0, n).
std::vector<int64_t> ComplementIndices(const std::vector<int64_t>& indices, int64_t n);

}  // namespace geometry
}  // namespace t
}  // namespace open3d
