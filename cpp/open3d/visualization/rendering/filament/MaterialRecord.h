// How Open3DScene::AddGeometry draws a geometry (Open3D's MaterialRecord, reduced to what
// this renderer draws). `shader` picks the way:
//   "defaultUnlit"  meshes and plain point clouds in their colours (or base_color), no light
//   "defaultLit"    meshes lit by the scene's directional light plus an ambient term
//                   (vertex normals are computed when the mesh has none); point clouds
//                   are drawn unlit
//   "gaussianSplat" point clouds with the Gaussian attributes, through the splat pipeline
#pragma once

#include <Eigen/Core>

#include <string>

namespace open3d {
namespace visualization {
namespace rendering {

struct MaterialRecord {
    std::string shader = "defaultUnlit";
    /// Linear RGBA multiplied with the vertex colours (used alone where there are none).
    Eigen::Vector4f base_color{1.0f, 1.0f, 1.0f, 1.0f};
    /// Point clouds drawn as points: the side of each point's square in pixels.
    float point_size = 3.0f;
    /// "gaussianSplat": the highest SH band used (0-3; the cloud's own degree caps it).
    int gaussian_splat_sh_degree = 3;
    /// "gaussianSplat": Mip-Splatting's antialias (density compensation of the 0.3 px
    /// low-pass filter) for clouds trained with it.
    bool gaussian_splat_antialias = false;
};

/// The shader names MaterialRecord::shader accepts.
inline constexpr const char* kShaderDefaultUnlit = "defaultUnlit";
inline constexpr const char* kShaderDefaultLit = "defaultLit";
inline constexpr const char* kShaderGaussianSplat = "gaussianSplat";

}  // namespace rendering
}  // namespace visualization
}  // namespace open3d
